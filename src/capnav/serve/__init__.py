"""The map server: one map kept loaded behind JSON endpoints and a web page (``capnav serve``).

Needs the ``serve`` extra (Starlette + uvicorn): ``pip install 'capnav[serve]'``.
"""

from capnav.serve.app import ServeConfig, create_app

__all__ = ["ServeConfig", "create_app"]
