"""`radar serve`: a read-only HTTP server for one results folder on 127.0.0.1, so the gallery's 3D viewer may
read meshes and lighting files (browsers refuse those reads to a page opened from disk)."""

from __future__ import annotations

import os
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Callable

from radar_cli.errors import InputError
from radar_cli.results import INDEX_FILE

HOST = "127.0.0.1"  # local only: the results are never offered to the network
MIME_TYPES = {".glb": "model/gltf-binary", ".gltf": "model/gltf+json", ".hdr": "image/vnd.radiance",
              ".js": "text/javascript", ".csv": "text/csv; charset=utf-8", ".json": "application/json",
              ".obj": "text/plain; charset=utf-8", ".mtl": "text/plain; charset=utf-8",
              ".npy": "application/octet-stream"}


class ResultsHandler(SimpleHTTPRequestHandler):
    """GET and HEAD of files inside the root only: no listings, no writes, nothing outside it via links."""

    extensions_map = {**SimpleHTTPRequestHandler.extensions_map, **MIME_TYPES}

    def __init__(self, *args, directory: str, quiet: bool = True, **kwargs):
        self.quiet = quiet
        super().__init__(*args, directory=directory, **kwargs)

    def send_head(self):
        """404 for anything whose real path leaves the root (a symlink out), else the base class's answer."""
        root = os.path.realpath(self.directory)
        real = os.path.realpath(self.translate_path(self.path))
        if real != root and not real.startswith(root + os.sep):
            self.send_error(404, "File not found")
            return None
        return super().send_head()

    def list_directory(self, path):
        self.send_error(404, "No listing")
        return None

    def end_headers(self) -> None:
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("Cache-Control", "no-cache")  # a re-run of radar derender rewrites the gallery in place
        super().end_headers()

    def log_message(self, format: str, *args) -> None:  # noqa: A002 (the base class's name)
        if not self.quiet:
            super().log_message(format, *args)


def make_server(root: str | Path, port: int = 0, quiet: bool = True) -> ThreadingHTTPServer:
    """A server for `root` on 127.0.0.1:`port` (0: a free port; see server.server_address), not yet serving.

    Raises:
        InputError: `root` is not a results folder, or the port cannot be bound.
    """
    root = Path(root)
    if not (root / INDEX_FILE).is_file():
        raise InputError(f"{root}: not a results folder (no {INDEX_FILE}; run `radar derender ... --out {root}`)")
    handler = partial(ResultsHandler, directory=str(root.resolve()), quiet=quiet)
    try:
        return ThreadingHTTPServer((HOST, port), handler)
    except OSError as e:
        raise InputError(f"cannot listen on {HOST}:{port} ({e.strerror or e}); try another --port") from None


def serve(root: str | Path, port: int, say: Callable[[str], None], quiet: bool = True) -> None:
    """Serve `root` until interrupted, announcing the gallery's address through `say`."""
    server = make_server(root, port, quiet)
    host, bound = server.server_address[:2]
    assert isinstance(host, str)  # an IPv4 or IPv6 server: its address is text
    say(f"gallery: http://{host}:{bound}/{INDEX_FILE}  (read-only, this computer only; Ctrl-C stops)")
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
