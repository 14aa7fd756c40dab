"""The pipeline: `mpc run pipeline.yml` builds many models as a DAG, with a cache, parallel
workers and a status; `mpc ci` writes CI pipelines with one job per model.

plan (pipeline.yml → models and edges) · defaults (pipeline defaults into each definition) ·
dag (order, cycles, dependants) · fingerprint (what a build depends on) · freshness (what
an earlier build left that still holds) · stages (the registry of compile/test/deploy) ·
worker (one model's stages in a process) · runner (the scheduler) · store (the build
folder and state) · status · progress · ci · command (CLI glue). See specs/pipeline.md.
"""
