"""`radar fetch` through click's CliRunner against the fake Met server: exit codes, summary, files."""

from __future__ import annotations

import socket
import time

from click.testing import CliRunner

from radar_cli.cli import cli
from radar_cli.cli.fetch import fetch
from radar_cli.harvest.catalog import iter_images


def run(met_server, out, *extra: str):
    args = ["--out", str(out), "--api-url", met_server.api_url, "--rate", "0", "--no-progress",
            "--block-wait", "0.01", *extra]
    return CliRunner().invoke(fetch, args)


def test_fetch_writes_catalog_records_and_images(met_server, tmp_path):
    for i in (11, 12):
        met_server.add(i)
    met_server.add(13, kind="not_pd")
    met_server.fault("/api/v1/objects/12", "html403")
    result = run(met_server, tmp_path / "data", "--query", "vase", "--image", "small")
    assert result.exit_code == 0, result.output
    assert "found 3, fetched 2 images" in result.output and "not_public_domain 1" in result.output
    assert sorted(p.name for p in (tmp_path / "data" / "met").iterdir()) == [
        "11.jpg", "11.json", "12.jpg", "12.json", "13.json"]
    assert [e.object_id for e in iter_images(tmp_path / "data")] == [11, 12]


def test_fetch_exits_1_when_objects_fail(met_server, tmp_path):
    met_server.add(5)
    met_server.images[5] = b"\xff\xd8 not a jpeg"
    result = run(met_server, tmp_path / "data")
    assert result.exit_code == 1 and "failed 1" in result.output
    assert (tmp_path / "data" / "failures.csv").read_text().startswith("object_id,error\n5,corrupt image")


def test_fetch_rejects_bad_since_and_missing_ids_file(met_server, tmp_path):
    result = run(met_server, tmp_path / "data", "--since", "last week")
    assert result.exit_code == 2 and "YYYY-MM-DD" in result.output
    result = run(met_server, tmp_path / "data", "--ids", str(tmp_path / "nope.txt"))
    assert result.exit_code == 2


def test_bad_ids_file_is_one_line_error_through_the_radar_group(met_server, tmp_path):
    ids = tmp_path / "ids.txt"
    ids.write_text("12\nabc\n")
    result = CliRunner().invoke(cli, ["fetch", "--out", str(tmp_path / "data"), "--ids", str(ids),
                                      "--api-url", met_server.api_url, "--no-progress"])
    assert result.exit_code == 2
    assert result.output.strip().endswith("ids.txt:2: not an object id: 'abc'")


def _closed_port() -> int:
    """A port on 127.0.0.1 that nothing listens on (connections are refused)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_refused_connection_fails_in_one_stderr_line_within_seconds_leaving_nothing(tmp_path):
    out = tmp_path / "new" / "data"
    start = time.monotonic()
    result = CliRunner().invoke(cli, ["fetch", "--out", str(out), "--api-url", f"http://127.0.0.1:{_closed_port()}",
                                      "--no-progress"])
    elapsed = time.monotonic() - start
    assert result.exit_code == 1 and result.stdout == ""
    assert result.stderr.count("\n") == 1 and "cannot connect (Connection refused" in result.stderr
    assert elapsed < 2.5, elapsed  # one retry, no long backoff
    assert not (tmp_path / "new").exists()  # no folder, no .fetch.lock, no empty catalog.sqlite


def test_refused_connection_keeps_an_existing_folder_as_it_was(tmp_path):
    out = tmp_path / "data"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    result = CliRunner().invoke(cli, ["fetch", "--out", str(out), "--api-url", f"http://127.0.0.1:{_closed_port()}",
                                      "--no-progress"])
    assert result.exit_code == 1
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_api_url_that_is_not_a_url_creates_nothing(tmp_path):
    result = CliRunner().invoke(cli, ["fetch", "--out", str(tmp_path / "data"), "--api-url", "notaurl"])
    assert result.exit_code == 2 and result.stdout == ""
    assert result.stderr.strip() == "Error: --api-url 'notaurl': not an http(s) URL"
    assert not (tmp_path / "data").exists()


def test_a_run_removes_its_lock_and_the_temp_files_of_a_killed_one(met_server, tmp_path):
    met_server.add(3)
    out = tmp_path / "data"
    (out / "met").mkdir(parents=True)
    leftovers = [out / ".failures.csv.ab12cd34.tmp.csv", out / "met" / ".3.json.zz_99xyz.tmp.json"]
    for path in leftovers:
        path.write_bytes(b"partial")
    (out / ".notes.tmp").write_text("not radar's")
    assert run(met_server, out).exit_code == 0
    assert not any(p.exists() for p in leftovers) and (out / ".notes.tmp").is_file()
    assert not (out / ".fetch.lock").exists() and (out / "catalog.sqlite").is_file()
