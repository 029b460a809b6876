"""A fake Met Collection API on 127.0.0.1 that serves object records and injects faults.

Object records are built by the tests in the schema of the API's recorded responses (met_records.py), with
`objectID`, image URLs and a few fields rewritten per fake object; every test runs on them, and once more on the
real recorded responses from ../shared/data/met_api/ when those are present. Faults are queued per URL path and
consumed one per request, so "fails twice, then works" is `server.fault("/api/v1/objects/7", "500", "503")`.
"""

from __future__ import annotations

import hashlib
import io
import json
import threading
import time
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any, Callable, Iterator
from urllib.parse import parse_qs, urlparse

import pytest
from PIL import Image

from radar_cli.harvest.client import ClientConfig
from radar_cli.harvest.harvester import HarvestConfig

from . import met_records

TEMPLATES = {  # recorded responses: two public-domain objects with images, one not public domain
    "pd_scroll": "objects_45734_quail_and_millet_2020.json",
    "pd_cover": "objects_47533_porcelain_cover_2021.json",
    "not_pd": "objects_1027_not_public_domain_raw.json",
}
BLOCK_PAGE = "error_incapsula_block_2019.html"
DEPARTMENTS = "departments_from_readme.json"
FAST = ClientConfig(rate=0, timeout=1.0, retries=3, backoff_base=0.001, backoff_cap=0.01, block_wait=0.01,
                    block_retries=2, max_bytes=1_000_000)


def jpeg(seed: int, size: int = 24) -> bytes:
    """A small deterministic JPEG for one object."""
    im = Image.new("RGB", (size, size), ((seed * 37) % 256, (seed * 91) % 256, (seed * 53) % 256))
    buf = io.BytesIO()
    im.save(buf, format="JPEG", quality=90)
    return buf.getvalue()


@dataclass
class FakeMet:
    """State of the fake API: objects, images, the fake search cap and queued faults."""

    templates: dict[str, dict[str, Any]]
    departments: list[dict[str, Any]]
    block_page: bytes
    cap: int = 10_000
    objects: dict[int, dict[str, Any]] = field(default_factory=dict)
    images: dict[int, bytes] = field(default_factory=dict)
    withdrawn: set[int] = field(default_factory=set)
    faults: dict[str, list[str]] = field(default_factory=dict)
    log: list[str] = field(default_factory=list)
    agents: set[str] = field(default_factory=set)
    url: str = ""
    delay: float = 0.0
    lock: threading.Lock = field(default_factory=threading.Lock)

    @property
    def api_url(self) -> str:
        return self.url + "/api/"

    def add(self, object_id: int, kind: str = "pd_scroll", department: int = 6, year: int = 1700,
            image: bytes | None = None, **fields: Any) -> dict[str, Any]:
        """Add an object built from a recorded response; its image is served at /images/<id>.jpg."""
        record = json.loads(json.dumps(self.templates[kind]))
        record.update(objectID=object_id, objectBeginDate=year, objectEndDate=year + 10,
                      objectURL=f"https://www.metmuseum.org/art/collection/search/{object_id}")
        record["_departmentId"] = department
        if record["primaryImage"]:
            record["primaryImage"] = f"{self.url}/images/{object_id}.jpg"
            record["primaryImageSmall"] = f"{self.url}/images/{object_id}-small.jpg"
        record.update(fields)
        self.objects[object_id] = record
        self.images[object_id] = image if image is not None else jpeg(object_id)
        return record

    def fault(self, path: str, *kinds: str) -> None:
        """Queue faults for the next requests to `path` (e.g. "/api/v1/objects/7" or "/images/7.jpg")."""
        self.faults.setdefault(path, []).extend(kinds)

    def hits(self, path: str) -> int:
        """How many requests went to exactly `path`."""
        return self.log.count(path)

    def record_body(self, object_id: int) -> bytes:
        record = {k: v for k, v in self.objects[object_id].items() if not k.startswith("_")}
        return json.dumps(record, ensure_ascii=False, separators=(",", ":")).encode("utf-8")

    def search(self, query: dict[str, str]) -> dict[str, Any]:
        hits = sorted(i for i, r in self.objects.items() if self._matches(r, query))
        offset, limit = int(query.get("offset", 0)), int(query.get("limit", 100))
        page = hits[offset: min(offset + limit, self.cap)]
        return {"total": len(hits), "objectIDs": page or None}  # null, not [], like the real API

    @staticmethod
    def _matches(record: dict[str, Any], query: dict[str, str]) -> bool:
        if "departmentId" in query and record["_departmentId"] != int(query["departmentId"]):
            return False
        lo, hi = int(query.get("dateBegin", -10**6)), int(query.get("dateEnd", 10**6))
        return lo <= record["objectBeginDate"] <= hi


class MetHandler(BaseHTTPRequestHandler):
    """Serves one FakeMet (set as the `met` class attribute by a subclass)."""

    met: FakeMet
    protocol_version = "HTTP/1.1"
    disable_nagle_algorithm = True  # headers and body go out as separate writes: avoid 40 ms ACK stalls

    def log_message(self, *args: Any) -> None:  # keep pytest output quiet
        pass

    def send(self, status: int, body: bytes, ctype: str = "application/json",
             headers: dict[str, str] | None = None, declared: int | None = None) -> None:
        self.send_response(status)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body) if declared is None else declared))
        for k, v in (headers or {}).items():
            self.send_header(k, v)
        self.end_headers()
        self.wfile.write(body)

    def do_GET(self) -> None:  # noqa: N802 (http.server's name)
        url = urlparse(self.path)
        with self.met.lock:
            self.met.log.append(url.path)
            self.met.agents.add(self.headers.get("User-Agent", ""))
            queue = self.met.faults.get(url.path)
            fault = queue.pop(0) if queue else ""
        if self.met.delay:
            time.sleep(self.met.delay)
        try:
            if fault:
                self.inject(fault)
            else:
                self.route(url.path, {k: v[0] for k, v in parse_qs(url.query).items()})
        except (BrokenPipeError, ConnectionResetError):
            pass

    def inject(self, fault: str) -> None:
        if fault in ("500", "503"):
            self.send(int(fault), b'{"message":"Internal Server Error"}')
        elif fault.startswith("429"):  # "429" or "429:<Retry-After seconds>"
            self.send(429, b"Too Many Requests", "text/plain", {"Retry-After": (fault + ":0").split(":")[1]})
        elif fault == "html403":
            self.send(403, self.met.block_page, "text/html")
        elif fault == "html200":
            self.send(200, self.met.block_page, "text/html")
        elif fault == "malformed":
            self.send(200, b'{"objectID": 1, "title": "unterminated')
        elif fault == "truncated":
            self.send(200, b'{"total": 3, "objec', declared=400)
            self.close_connection = True
        elif fault == "slow":  # a body that trickles in for longer than the client's per-attempt timeout
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", "400")
            self.end_headers()
            for _ in range(40):
                self.wfile.write(b" ")
                self.wfile.flush()
                time.sleep(0.05)
            self.close_connection = True
        else:
            raise AssertionError(f"unknown fault {fault}")

    def route(self, path: str, query: dict[str, str]) -> None:
        if path == "/api/v1.1/search":
            self.send(200, json.dumps(self.met.search(query)).encode())
        elif path == "/api/v1/departments":
            self.send(200, json.dumps({"departments": self.met.departments}).encode())
        elif path == "/api/v1/objects":
            since = query.get("metadataDate", "")
            ids = sorted(i for i, r in self.met.objects.items() if r["metadataDate"][:10] >= since)
            self.send(200, json.dumps({"total": len(ids), "objectIDs": ids or None}).encode())
        elif path.startswith("/api/v1/objects/"):
            self.object(path.rsplit("/", 1)[1])
        elif path.startswith("/images/"):
            self.image(path.rsplit("/", 1)[1].split(".")[0].replace("-small", ""))
        else:
            self.send(404, b"<html>Not found</html>", "text/html")

    def object(self, tail: str) -> None:
        if not tail.isdigit():
            self.send(400, b'{"message":"could not parse objectID"}')
        elif int(tail) in self.met.withdrawn or int(tail) not in self.met.objects:
            self.send(404, b'{"message":"ObjectID not found"}')
        else:
            self.send(200, self.met.record_body(int(tail)))

    def image(self, tail: str) -> None:
        body = self.met.images.get(int(tail)) if tail.isdigit() else None
        if body is None:
            self.send(404, b"<html>Not found</html>", "text/html")
            return
        etag = '"%s"' % hashlib.sha256(body).hexdigest()[:16]
        if self.headers.get("If-None-Match") == etag:
            self.send(304, b"", "image/jpeg", {"ETag": etag})
        else:
            self.send(200, body, "image/jpeg", {"ETag": etag})


class QuietServer(ThreadingHTTPServer):
    """Clients that hang up mid-body (timeouts, size limits) are expected: no tracebacks on stderr."""

    daemon_threads = True

    def handle_error(self, request: Any, client_address: Any) -> None:
        pass


def recorded_responses(folder: Path) -> FakeMet:
    """A FakeMet serving the recorded responses of `folder` (../shared/data/met_api)."""
    templates = {k: json.loads((folder / name).read_text(encoding="utf-8")) for k, name in TEMPLATES.items()}
    departments = json.loads((folder / DEPARTMENTS).read_text(encoding="utf-8"))["departments"]
    return FakeMet(templates, departments, (folder / BLOCK_PAGE).read_bytes())


@pytest.fixture(params=["built", "recorded"])
def met_server(request: pytest.FixtureRequest, shared_data: Callable[..., Path]) -> Iterator[FakeMet]:
    """A running fake Met API on the tests' own records, then on the recorded ones (skipped when absent)."""
    if request.param == "recorded":
        met = recorded_responses(shared_data("data", "met_api"))
    else:
        met = FakeMet({kind: met_records.object_record(kind) for kind in met_records.KINDS},
                      met_records.departments(), met_records.BLOCK_PAGE)
    server = QuietServer(("127.0.0.1", 0), type("Handler", (MetHandler,), {"met": met}))
    met.url = f"http://127.0.0.1:{server.server_address[1]}"
    thread = threading.Thread(target=server.serve_forever, args=(0.05,), daemon=True)
    thread.start()
    try:
        yield met
    finally:
        server.shutdown()
        server.server_close()


@pytest.fixture
def harvest_config(met_server: FakeMet, tmp_path: Path) -> Callable[..., HarvestConfig]:
    """`harvest_config(**overrides)`: a fast HarvestConfig pointed at the fake server, writing to tmp_path."""

    def make(**overrides: Any) -> HarvestConfig:
        base: dict[str, Any] = dict(out=tmp_path / "data", api_url=met_server.api_url, api_client=FAST,
                                    image_client=FAST, progress=False)
        return HarvestConfig(**{**base, **overrides})

    return make
