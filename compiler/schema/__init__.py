"""The schema of the definition language: AST nodes that keep their spans.

One module per part: `base` (nodes, screening, error mapping), `assembly`
(input_models, assemble), `exports`, `editing` (materials, frames, joints,
collisions, visuals), `annotations` (sensors, poses, submechanisms, annotations,
post_processing), `release` (test, deployment), `definition` (the file roots).
"""

from mpc.compiler.schema.definition import (
    Definition,
    ModelSection,
    Pipeline,
    validate,
    validate_pipeline,
)

__all__ = ["Definition", "ModelSection", "Pipeline", "validate", "validate_pipeline"]
