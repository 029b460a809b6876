"""The harvest pipeline: search -> object records -> images, resumable from the catalog at every step.

Layout of the output folder:
    DATA/catalog.sqlite        one row per object (see catalog.py)
    DATA/met/<id>.json         the object record exactly as the API sent it
    DATA/met/<id>.jpg          the validated image (name from the numeric id only)
    DATA/met/<id>/<id>_<k>.jpg with --images all, an object with several images: the primary (k = 0) and its
                               additionalImages (k = 1, 2, ...), see views.py
    DATA/failures.csv          object_id,error of the objects that failed (rewritten at the end of each run)
    DATA/.fetch.lock           held while a run writes the folder (one run per folder at a time), then removed
"""

from __future__ import annotations

import csv
import fcntl
import io
import os
from collections import Counter
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator, Literal

from tqdm import tqdm

from radar_cli.errors import InputError, NetworkError
from radar_cli.fileio import remove_stale_temps, write_bytes, write_text
from radar_cli.harvest.catalog import CATALOG_NAME, OBJECTS_DIR, Catalog, open_catalog
from radar_cli.harvest.client import ClientConfig, FetchError, HttpClient
from radar_cli.harvest.dimensions import size_of_record
from radar_cli.harvest.images import MAX_PIXELS, download_image
from radar_cli.harvest.met_api import DEFAULT_API_URL, MetApi
from radar_cli.harvest.views import ViewStage, read_stored_record

LOCK_FILE = ".fetch.lock"
MAX_CONSECUTIVE_FAILURES = 20  # an outage: stop instead of marking every remaining object failed


@dataclass(frozen=True)
class HarvestConfig:
    """What to harvest and how."""

    out: Path
    """Output folder (created)."""
    query: str = "vase"
    """The search term (`q`)."""
    limit: int | None = None
    """Harvest only the first N search results (None: all)."""
    department: int | None = None
    """Restrict the search to one department id."""
    public_domain_only: bool = True
    """Keep only public-domain (CC0) objects; others are skipped with reason not_public_domain."""
    image: Literal["original", "small"] = "original"
    """primaryImage (up to 4000 px) or primaryImageSmall (~600 px)."""
    images: Literal["primary", "all"] = "primary"
    """`all`: also download additionalImages as views (DATA/met/<id>/ for objects with several images)."""
    api_url: str = DEFAULT_API_URL
    """API base URL (point it at a local server for offline runs)."""
    since: str | None = None
    """YYYY-MM-DD: refetch the records of known objects changed since then."""
    ids_file: Path | None = None
    """A file of object ids (one per line) used instead of the search."""
    page_size: int = 500
    """Search page size."""
    result_cap: int = 10_000
    """Results one search query can page through; bigger queries are split."""
    max_pixels: int = MAX_PIXELS
    """Largest image accepted, in pixels."""
    api_client: ClientConfig = ClientConfig()
    """Pacing, retries and limits for the API host."""
    image_client: ClientConfig = ClientConfig(max_bytes=50 * 1024 * 1024)
    """Pacing, retries and limits for the image host (its own budget)."""
    progress: bool = True
    """Show tqdm progress bars."""


@dataclass
class Summary:
    """What a run did, and the catalog totals after it."""

    found: int = 0
    records_fetched: int = 0
    images_fetched: int = 0
    images_unchanged: int = 0
    views_fetched: int = 0
    views_unchanged: int = 0
    view_counts: dict[str, int] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    skipped: Counter[str] = field(default_factory=Counter)
    interrupted: bool = False
    aborted: str = ""

    @property
    def failed(self) -> int:
        """Objects in the failed state."""
        return self.counts.get("failed", 0)

    @property
    def views_failed(self) -> int:
        """Additional views in the failed state."""
        return self.view_counts.get("failed", 0)

    def line(self) -> str:
        """The one-line summary printed at the end of a run."""
        skipped = ", ".join(f"{k} {v}" for k, v in sorted(self.skipped.items())) or "none"
        text = (f"found {self.found}, fetched {self.images_fetched} images ({self.records_fetched} records, "
                f"{self.images_unchanged} images unchanged), have {self.counts.get('image', 0)} images; "
                f"skipped {sum(self.skipped.values())} ({skipped}); failed {self.failed}")
        if self.counts.get("searched", 0) or self.counts.get("record", 0):
            text += f"; pending {self.counts.get('searched', 0) + self.counts.get('record', 0)}"
        if self.view_counts:
            text += (f"; views: fetched {self.views_fetched} ({self.views_unchanged} unchanged), have "
                     f"{self.view_counts.get('image', 0)}, skipped {self.view_counts.get('skipped', 0)}, "
                     f"failed {self.views_failed}, pending {self.view_counts.get('pending', 0)}")
        if self.interrupted:
            text += " [interrupted: rerun to resume]"
        if self.aborted:
            text += f" [stopped: {self.aborted}]"
        return text


def read_ids_file(path: Path) -> list[int]:
    """Object ids from a text file, one per line; blank lines and `#` comments ignored."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as e:
        raise InputError(f"{path}: cannot read ids file ({e.strerror})") from None
    ids = []
    for n, line in enumerate(lines, 1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        if not text.isdigit() or int(text) <= 0:
            raise InputError(f"{path}:{n}: not an object id: {text!r}")
        ids.append(int(text))
    return list(dict.fromkeys(ids))


class Harvester:
    """Runs the three stages against one catalog; every step is recorded before the next one starts."""

    def __init__(self, config: HarvestConfig, catalog: Catalog, log: Callable[[str], None]):
        self.config = config
        self.catalog = catalog
        self.log = log
        self.folder = Path(config.out) / OBJECTS_DIR
        self.api = MetApi(HttpClient(config.api_client), config.api_url, config.page_size, config.result_cap,
                          warn=log)
        self.images = HttpClient(config.image_client)
        self.summary = Summary()
        self._consecutive_failures = 0

    def _bar(self, total: int | None, desc: str, unit: str) -> tqdm:
        return tqdm(total=total, desc=desc, unit=unit, disable=not self.config.progress, leave=False)

    def search(self) -> None:
        """Stage 1: find candidate ids (search or ids file) and add the new ones to the catalog."""
        cfg = self.config
        if cfg.ids_file is not None:
            ids = read_ids_file(Path(cfg.ids_file))
        else:
            with self._bar(None, "search", "id") as bar:
                ids = self.api.search(cfg.query, cfg.department, on_page=bar.update)
        if cfg.limit is not None:
            ids = ids[: cfg.limit]
        self.summary.found = len(ids)
        asked = cfg.query if cfg.ids_file is None else f"ids from {cfg.ids_file}"
        previous = self.catalog.get_meta("query")
        if previous is not None and previous != asked:
            self.log(f"note: {cfg.out} was harvested for {previous!r} before; adding {asked!r} to the same catalog")
        self.catalog.set_meta("query", asked)
        self.catalog.add_searched(ids)
        if cfg.since:
            changed = self.api.changed_since(cfg.since, cfg.department)
            n = self.catalog.mark_changed(i for i in ids if i in changed)
            self.log(f"--since {cfg.since}: {n} known objects changed, their records will be refetched")

    def records(self) -> None:
        """Stage 2: fetch, store and judge the object record of every pending id."""
        pending = self.catalog.pending_records()
        with self._bar(len(pending), "records", "rec") as bar:
            for object_id in pending:
                self._guard(self._record, object_id)
                bar.update()

    def images_stage(self) -> None:
        """Stage 3: download, validate and store the image of every object with a kept record."""
        pending = self.catalog.pending_images()
        with self._bar(len(pending), "images", "img") as bar:
            for object_id in pending:
                self._guard(self._image, object_id)
                bar.update()

    def views_stage(self) -> None:
        """Stage 4 (`--images all`): the additional images of every object with a stored image."""
        ViewStage(Path(self.config.out), OBJECTS_DIR, self.catalog, self.images, self.config.max_pixels,
                  self.summary, self.config.progress, MAX_CONSECUTIVE_FAILURES).run()

    def fill_sizes(self) -> None:
        """Parse the size of stored records that have none yet (catalogs written before sizes were kept)."""
        for row in self.catalog.rows():
            if row["size"] is None and row["record_path"]:
                record = read_stored_record(Path(self.config.out), row["record_path"])
                if record is not None:
                    self.catalog.set_size(row["object_id"], size_of_record(record))

    def _guard(self, step: Callable[[int], None], object_id: int) -> None:
        """Run one object's step; a network failure marks it failed, too many in a row stop the run."""
        try:
            step(object_id)
            self._consecutive_failures = 0
        except FetchError as e:
            self._fail(object_id, str(e))
            self._consecutive_failures += 1
            if self._consecutive_failures >= MAX_CONSECUTIVE_FAILURES:
                raise NetworkError(f"{self._consecutive_failures} objects failed in a row (last: {e})") from None

    def _fail(self, object_id: int, error: str) -> None:
        self.catalog.set_state(object_id, "failed", error)
        tqdm.write(f"object {object_id}: failed: {error}")

    def _record(self, object_id: int) -> None:
        reply = self.api.object(object_id)
        if reply.status == 404:
            self.catalog.set_state(object_id, "skipped", "not_found")
            return
        if reply.status == 400:
            self.catalog.set_state(object_id, "skipped", "bad_id")
            return
        record = reply.data
        if reply.status != 200 or not isinstance(record, dict) or record.get("objectID") != object_id:
            self._fail(object_id, f"unexpected object record (HTTP {reply.status}): {reply.body[:80]!r}")
            return
        record_path = f"{OBJECTS_DIR}/{object_id}.json"
        write_bytes(Path(self.config.out) / record_path, reply.body)  # verbatim, as the API sent it
        field_name = "primaryImage" if self.config.image == "original" else "primaryImageSmall"
        image_url = str(record.get(field_name) or "")
        state, reason = "record", ""
        if self.config.public_domain_only and record.get("isPublicDomain") is not True:
            state, reason = "skipped", "not_public_domain"
        elif not image_url:
            state, reason = "skipped", "no_image"
        if state == "skipped":
            self._drop_image(object_id)  # a --since refetch may withdraw an image kept before
        self.catalog.set_record(object_id, record, record_path, image_url, state, reason)
        self.summary.records_fetched += 1

    def _drop_image(self, object_id: int) -> None:
        row = self.catalog.get(object_id)
        if row is not None and row["image_path"]:
            (Path(self.config.out) / row["image_path"]).unlink(missing_ok=True)
            self.catalog.clear_image(object_id)

    def _image(self, object_id: int) -> None:
        row = self.catalog.get(object_id)
        assert row is not None and row["image_url"], object_id
        old = Path(self.config.out) / row["image_path"] if row["image_path"] else None
        got = download_image(self.images, row["image_url"], row["etag"], old, self.folder, object_id,
                             self.config.max_pixels)
        if got.outcome == "unchanged":
            self.catalog.set_image(object_id, row["image_path"], row["bytes"], row["sha256"], row["etag"])
            self.summary.images_unchanged += 1
        elif got.outcome == "skipped":
            self.catalog.set_state(object_id, "skipped", got.reason)
            if got.message:
                tqdm.write(f"object {object_id}: skipped: {got.message}")
        elif got.outcome == "failed":
            self._fail(object_id, got.reason)
        else:
            assert got.stored is not None
            rel = got.stored.path.relative_to(Path(self.config.out)).as_posix()
            self.catalog.set_image(object_id, rel, got.stored.size, got.stored.sha256, got.etag)
            self.summary.images_fetched += 1


def _write_failures(catalog: Catalog, out: Path) -> None:
    rows = [r for r in catalog.rows() if r["state"] == "failed"]
    views = [v for v in catalog.views() if v["state"] == "failed"]
    path = out / "failures.csv"
    if not rows and not views:
        path.unlink(missing_ok=True)
        return
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(["object_id", "error"])
    writer.writerows([r["object_id"], r["reason"]] for r in rows)
    writer.writerows([v["object_id"], f"view {v['view']}: {v['reason']}"] for v in views)
    write_text(path, buf.getvalue())


@contextmanager
def _only_run(out: Path) -> Iterator[None]:
    """Hold an exclusive lock on the folder for the run (released by the OS even on SIGKILL); the lock file is
    removed when the run ends."""
    path = out / LOCK_FILE
    with open(path, "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            if os.fstat(lock.fileno()).st_ino != os.stat(path).st_ino:  # a run that just ended removed it
                raise BlockingIOError
        except (BlockingIOError, FileNotFoundError):
            raise InputError(f"{out}: another `radar fetch` is writing this folder") from None
        try:
            yield
        finally:
            path.unlink(missing_ok=True)  # still holding the lock: no other run can have taken it


def harvest(config: HarvestConfig, log: Callable[[str], None] = tqdm.write) -> Summary:
    """Harvest a Met collection query into `config.out`, resuming whatever an earlier run left.

    Ctrl-C stops between requests; the summary then says `interrupted` and a rerun resumes.

    Args:
        config: what to harvest and how.
        log: where one-line notices go.

    Returns:
        The run summary (catalog totals included).

    Raises:
        InputError: --api-url is not an http(s) URL, or the folder cannot be written. NetworkError: the API failed
            before anything was harvested; the folder is then left as it was (a new one is not created).
    """
    out = Path(config.out)
    if not config.api_url.startswith(("http://", "https://")):
        raise InputError(f"--api-url {config.api_url!r}: not an http(s) URL")
    created = [p for p in (out, *out.parents) if not p.exists()]
    fresh = not (out / CATALOG_NAME).exists()
    try:
        out.mkdir(parents=True, exist_ok=True)
        with _only_run(out):
            return _harvest(config, out, log, fresh)
    except NetworkError:
        _remove_run(out, created)
        raise
    except OSError as e:  # disk full, permissions: the catalog stays consistent, a rerun resumes
        raise InputError(f"{out}: cannot write the harvest ({e})") from None


def _remove_run(out: Path, created: list[Path]) -> None:
    """Remove the empty catalog and the folders of a run that harvested nothing."""
    for suffix in ("", "-wal", "-shm"):
        (out / (CATALOG_NAME + suffix)).unlink(missing_ok=True)
    for folder in created:  # deepest first
        try:
            folder.rmdir()
        except OSError:
            break


def _harvest(config: HarvestConfig, out: Path, log: Callable[[str], None], fresh: bool) -> Summary:
    remove_stale_temps(out, recursive=True)  # what a killed run was writing
    with open_catalog(out) as catalog:
        harvester = Harvester(config, catalog, log)
        summary = harvester.summary
        try:
            harvester.search()
            harvester.records()
            harvester.images_stage()
            harvester.fill_sizes()
            if config.images == "all":
                harvester.views_stage()
        except KeyboardInterrupt:
            summary.interrupted = True
        except NetworkError as e:
            if fresh and not any(catalog.counts().values()):
                raise  # nothing harvested: no catalog is left behind
            summary.aborted = str(e)
        summary.counts = catalog.counts()
        summary.skipped = catalog.skip_reasons()
        summary.view_counts = catalog.view_counts()
        _write_failures(catalog, out)
    return summary
