"""`radar serve`: files of the results folder with the types browsers need, nothing else (no listings, no
writes, no way out through a link), on 127.0.0.1 only."""

from __future__ import annotations

import threading
import urllib.error
import urllib.request
from pathlib import Path

import pytest
from click.testing import CliRunner

from radar_cli.cli import cli
from radar_cli.derender.present.server import make_server
from radar_cli.errors import InputError


@pytest.fixture
def served(tmp_path: Path):
    root = tmp_path / "results"
    (root / "vase").mkdir(parents=True)
    (root / "index.html").write_text("<!DOCTYPE html><title>t</title>")
    (root / "vase" / "mesh.glb").write_bytes(b"glTF" + bytes(16))
    (root / "vase" / "env_viewer.hdr").write_bytes(b"#?RADIANCE\n")
    (tmp_path / "secret.txt").write_text("outside")
    (root / "vase" / "link.txt").symlink_to(tmp_path / "secret.txt")
    server = make_server(root, 0)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    host, port = server.server_address[:2]
    yield f"http://{host}:{port}"
    server.shutdown()
    server.server_close()


def fetch(url: str, method: str = "GET") -> tuple[int, str, bytes]:
    try:
        with urllib.request.urlopen(urllib.request.Request(url, method=method), timeout=10) as r:
            return r.status, r.headers.get("Content-Type", ""), r.read()
    except urllib.error.HTTPError as e:
        return e.code, "", b""


def test_serves_files_with_their_types(served: str) -> None:
    assert served.startswith("http://127.0.0.1:")
    assert fetch(served + "/index.html")[:2] == (200, "text/html")
    status, ctype, body = fetch(served + "/vase/mesh.glb")
    assert (status, ctype, body[:4]) == (200, "model/gltf-binary", b"glTF")
    assert fetch(served + "/vase/env_viewer.hdr")[:2] == (200, "image/vnd.radiance")


def test_no_listing_no_writes_no_escape(served: str) -> None:
    assert fetch(served + "/vase/")[0] == 404
    assert fetch(served + "/vase/link.txt")[0] == 404  # a symlink leading out of the folder
    assert fetch(served + "/../secret.txt")[0] == 404
    assert fetch(served + "/index.html", "PUT")[0] == 501
    assert fetch(served + "/index.html", "POST")[0] == 501
    assert fetch(served + "/index.html", "DELETE")[0] == 501


def test_refuses_a_folder_without_a_gallery(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="not a results folder"):
        make_server(tmp_path, 0)
    result = CliRunner().invoke(cli, ["serve", str(tmp_path), "--port", "0"])
    assert result.exit_code == 2 and "not a results folder" in result.output
