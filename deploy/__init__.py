"""mpc.deploy: built models → their git repositories, merge requests, mirrors.

The entry point is `deploy_model(program, built, settings, sink, *, protocol_markdown,
tests_failed) -> DeployResult`; `DeploySettings` holds the pipeline-level settings.
"""

from mpc.deploy.model import DeployResult, deploy_model
from mpc.deploy.settings import DeploySettings

__all__ = ["DeployResult", "DeploySettings", "deploy_model"]
