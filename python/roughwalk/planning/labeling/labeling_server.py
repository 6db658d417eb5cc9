"""The labelling web app's server: the standard library's HTTP server on the loopback only.

Routes:

* ``GET /`` and ``GET /static/<file>``: the page (HTML, JS, CSS shipped as package data);
* ``GET /api/state``: counts, the live model's agreement, the pair on show;
* ``POST /api/label`` with ``{"token": ..., "choice": "left"|"right"|"equal"|"skip"}``;
* ``POST /api/undo``.

Answers are JSON; errors are ``{"error": message}`` with status 400 (bad
request), 409 (the pair is no longer on show; the body holds the fresh
state) or 500. The server binds 127.0.0.1 only, answers only requests whose
Host header names it (so that a web page elsewhere cannot reach it by DNS
rebinding), and takes only JSON POSTs (which other sites' pages cannot send
without the CORS permission it never gives).
"""

from __future__ import annotations

import json
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from typing import Any

from roughwalk.errors import InvalidArgumentError, RoughwalkError
from roughwalk.planning.labeling.labeling_session import LabelingSession, StalePairError

__all__ = ["LabelingServer", "HOST"]

HOST = "127.0.0.1"
_STATIC = {
    "index.html": "text/html; charset=utf-8",
    "app.js": "text/javascript; charset=utf-8",
    "style.css": "text/css; charset=utf-8",
}
_MAX_BODY = 64 * 1024


def _static(name: str) -> bytes:
    return resources.files("roughwalk.planning.labeling").joinpath("static", name).read_bytes()


class _Handler(BaseHTTPRequestHandler):
    server: _Server
    protocol_version = "HTTP/1.1"

    def log_message(self, format: str, *args: Any) -> None:  # noqa: A002
        if self.server.verbose:
            super().log_message(format, *args)

    # ------------------------------------------------------------- helpers
    def _host_ok(self) -> bool:
        port = self.server.server_address[1]
        allowed = {f"{HOST}:{port}", f"localhost:{port}"}
        if self.headers.get("Host", "") in allowed:
            return True
        self._send_json({"error": "unknown host"}, HTTPStatus.FORBIDDEN)
        return False

    def _send(self, body: bytes, content_type: str, status: HTTPStatus = HTTPStatus.OK) -> None:
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.end_headers()
        self.wfile.write(body)

    def _send_json(self, data: Any, status: HTTPStatus = HTTPStatus.OK) -> None:
        body = json.dumps(data, allow_nan=False).encode()
        self._send(body, "application/json", status)

    def _read_json(self) -> dict[str, Any]:
        if not self.headers.get("Content-Type", "").startswith("application/json"):
            raise InvalidArgumentError("POST bodies must be application/json")
        length = int(self.headers.get("Content-Length") or 0)
        if length > _MAX_BODY:
            raise InvalidArgumentError(f"request body of {length} bytes is too large")
        raw = self.rfile.read(length) if length else b"{}"
        try:
            data = json.loads(raw or b"{}")
        except json.JSONDecodeError as e:
            raise InvalidArgumentError(f"request body is not JSON: {e}") from None
        if not isinstance(data, dict):
            raise InvalidArgumentError("request body must be a JSON object")
        return data

    # -------------------------------------------------------------- routes
    def do_GET(self) -> None:  # noqa: N802
        if not self._host_ok():
            return
        path = self.path.split("?", 1)[0]
        if path in ("/", "/index.html"):
            self._send(_static("index.html"), _STATIC["index.html"])
        elif path.startswith("/static/") and path[len("/static/") :] in _STATIC:
            name = path[len("/static/") :]
            self._send(_static(name), _STATIC[name])
        elif path == "/api/state":
            self._answer(self.server.session.state)
        else:
            self._send_json({"error": f"no such page: {path}"}, HTTPStatus.NOT_FOUND)

    def do_POST(self) -> None:  # noqa: N802
        if not self._host_ok():
            return
        path = self.path.split("?", 1)[0]
        session = self.server.session
        if path == "/api/label":

            def act() -> dict[str, Any]:
                body = self._read_json()
                return session.label(str(body.get("token", "")), str(body.get("choice", "")))

            self._answer(act)
        elif path == "/api/undo":

            def undo() -> dict[str, Any]:
                self._read_json()
                return session.undo()

            self._answer(undo)
        else:
            self._send_json({"error": f"no such action: {path}"}, HTTPStatus.NOT_FOUND)

    def _answer(self, action: Any) -> None:
        try:
            self._send_json(action())
        except StalePairError as e:
            self._send_json(
                {"error": str(e), "state": self.server.session.state()}, HTTPStatus.CONFLICT
            )
        except InvalidArgumentError as e:
            self._send_json({"error": str(e)}, HTTPStatus.BAD_REQUEST)
        except RoughwalkError as e:
            self._send_json({"error": str(e)}, HTTPStatus.INTERNAL_SERVER_ERROR)


class _Server(ThreadingHTTPServer):
    daemon_threads = True

    def __init__(self, port: int, session: LabelingSession, verbose: bool) -> None:
        self.session = session
        self.verbose = verbose
        super().__init__((HOST, port), _Handler)


class LabelingServer:
    """Serves a :class:`LabelingSession` at ``http://127.0.0.1:PORT/``.

    Parameters
    ----------
    session:
        The session to serve.
    port:
        TCP port; 0 lets the system choose a free one (see :attr:`url`).
    verbose:
        Log every request to stderr.

    """

    def __init__(self, session: LabelingSession, port: int = 0, verbose: bool = False) -> None:
        if not 0 <= port <= 65535:
            raise InvalidArgumentError(f"port must be in 0..65535, got {port}")
        try:
            self._httpd = _Server(port, session, verbose)
        except OSError as e:
            raise InvalidArgumentError(f"cannot listen on {HOST}:{port}: {e}") from None
        self.session = session
        self._thread: threading.Thread | None = None

    @property
    def port(self) -> int:
        """The port it listens on."""
        return int(self._httpd.server_address[1])

    @property
    def url(self) -> str:
        """The page's address."""
        return f"http://{HOST}:{self.port}/"

    def serve_forever(self) -> None:
        """Serve until :meth:`shutdown` is called from another thread (or Ctrl+C)."""
        self._httpd.serve_forever(poll_interval=0.2)

    def start(self) -> None:
        """Serve in a background thread."""
        self._thread = threading.Thread(target=self.serve_forever, daemon=True)
        self._thread.start()

    def shutdown(self) -> None:
        """Stop serving and release the port (judgements are already committed)."""
        if self._thread is not None:
            self._httpd.shutdown()
            self._thread.join(timeout=10)
            self._thread = None
        self._httpd.server_close()
