"""The SCM's REST and WebSocket API (FastAPI; OpenAPI at /docs) and its web app (static/):
create_app (main.py) mounts one APIRouter per resource (routes/) on the shared dependencies
(deps.py: the service, the logged-in user, the operator with a CSRF token)."""

from autodrive.scm.api.main import create_app

__all__ = ["create_app"]
