"""mpc.deploy: built models → their git repositories, merge requests, mirrors.

The entry point is `deploy_model(program, built, settings, sink, *, protocol_markdown,
tests_failed) -> DeployResult`; `DeploySettings` holds the pipeline-level settings.
Its names are imported when first used, so that `mpc`'s argument parser (which reads
cli/deploy.py) does not load git and the schema on every start.
"""

from __future__ import annotations

from typing import Any

__all__ = ["FORGES", "DeployResult", "DeploySettings", "deploy_model"]

FORGES = ("gitlab", "github", "none")  # how merge requests are made (a pipeline's `forge`, deploy/forges.py)


def __getattr__(name: str) -> Any:
    if name == "deploy_model":
        from mpc.deploy.model import deploy_model

        return deploy_model
    if name == "DeployResult":
        from mpc.deploy.result import DeployResult

        return DeployResult
    if name == "DeploySettings":
        from mpc.deploy.settings import DeploySettings

        return DeploySettings
    raise AttributeError(f"module 'mpc.deploy' has no attribute '{name}'")
