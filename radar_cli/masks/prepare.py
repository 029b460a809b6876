"""`radar masks` batch driver: a folder of photographs (or a `radar fetch` harvest) -> the training layout.

    PREPARED/<split>/<id>/image.png, mask.png, meta.json   accepted crops (split from the object id, ~78/22)
    PREPARED/rejected/<id>/...                              rejected crops, for review
    PREPARED/rejected.csv, failures.csv, summary.json, contact_sheet-NNN.png
    PREPARED/.records/<source>.json                         one per finished photo: what a resumed run skips
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import multiprocessing
import sys
import time
from collections import Counter
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Iterator

import cv2
from tqdm import tqdm

from radar_cli.dataset import safe_id, sample_ref, write_sample
from radar_cli.errors import InputError, NothingToDoError
from radar_cli.fileio import remove_stale_temps, write_json, write_text
from radar_cli.masks.contact_sheet import write_sheets
from radar_cli.masks.pipeline import Crop, Settings, process_photo

PHOTO_EXTENSIONS = (".jpg", ".jpeg", ".png", ".tif", ".tiff", ".webp", ".bmp")
TRAIN_PERCENT = 78  # the paper's 1,888 / 526 split
REJECTED = "rejected"
RECORDS = ".records"


@dataclass(frozen=True)
class Source:
    """One photograph to process: `key` is its sample-id stem, `attribution` goes into every crop's meta."""

    key: str
    path: Path
    attribution: dict = field(default_factory=dict)


@dataclass(frozen=True)
class DetectorSpec:
    """Which detector the workers build: `classical`, or `onnx` with a model file."""

    name: str = "classical"
    model: str | None = None


def catalog_sources(data_dir: Path) -> list[Source]:
    """The harvested images of a `radar fetch` folder, with attribution from its catalog."""
    from radar_cli.harvest.catalog import iter_images

    return [Source(f"met_{e.object_id}", e.image_path,
                   {"object_id": e.object_id, "title": e.title, "credit_line": e.credit_line,
                    "licence": e.licence, "object_url": e.object_url,
                    **({"size": e.size.to_dict()} if e.size is not None else {})})
            for e in iter_images(data_dir)]


def list_sources(data_dir: str | Path, exclude: Path | None = None) -> list[Source]:
    """The photographs under `data_dir`: from its harvest catalog if it has one, else every image file
    (except those under `exclude`, the output folder, should it lie inside `data_dir`)."""
    data_dir = Path(data_dir)
    if not data_dir.is_dir():
        raise InputError(f"{data_dir}: no such folder")
    from radar_cli.harvest.catalog import CATALOG_NAME

    if (data_dir / CATALOG_NAME).is_file():
        return catalog_sources(data_dir)
    skip = exclude.resolve() if exclude is not None else None
    files = sorted(p for p in data_dir.rglob("*") if p.is_file() and p.suffix.lower() in PHOTO_EXTENSIONS
                   and not (skip and p.resolve().is_relative_to(skip)))
    keys = Counter(safe_id(p.stem) for p in files)
    return [Source(safe_id(p.stem) if keys[safe_id(p.stem)] == 1 else safe_id(str(p.relative_to(data_dir))), p,
                   {"file": str(p.relative_to(data_dir))}) for p in files]


def split_for(key: str) -> str:
    """`train` or `test`, fixed by a hash of the source key (all crops of one photo share a split)."""
    return "train" if int(hashlib.sha256(key.encode()).hexdigest()[:8], 16) % 100 < TRAIN_PERCENT else "test"


_DETECTORS: dict = {}


def _detector(spec: DetectorSpec):
    """The detector callable for this process (built once: an ONNX session is costly)."""
    if spec not in _DETECTORS:
        if spec.name == "onnx":
            from radar_cli.masks.onnx import OnnxDetector

            _DETECTORS[spec] = OnnxDetector(spec.model)
        else:
            from radar_cli.masks.detect import detect

            _DETECTORS[spec] = detect
    return _DETECTORS[spec]


def _write_crop(out: Path, source: Source, crop: Crop, index: int, split: str) -> dict:
    """Write one crop (image, mask, meta.json) and return its record."""
    sample_id = source.key if index == 0 else f"{source.key}_{index}"
    folder_split = split if crop.accepted else REJECTED
    ref = sample_ref(out, folder_split, sample_id)
    write_sample(ref, crop.image, crop.mask)
    meta = {"source": str(source.path), "crop_box": crop.original_box(), "scores": crop.scores,
            "accepted": crop.accepted, "reasons": crop.reasons, "split": split, "attribution": source.attribution}
    write_json(ref.folder / "meta.json", meta)
    return {"id": sample_id, "folder": f"{folder_split}/{sample_id}", "accepted": crop.accepted,
            "reasons": crop.reasons, "scores": crop.scores, "split": split}


def process_source(out: Path, source: Source, settings: Settings, spec: DetectorSpec) -> dict:
    """Process one photo completely and write its record; a bad image becomes a `failed` record."""
    record: dict = {"source": str(source.path), "key": source.key, "crops": []}
    try:
        crops = process_photo(source.path, settings, _detector(spec))
    except InputError as e:
        record.update(status="failed", reason=str(e))
    except Exception as e:  # noqa: BLE001 - one odd photo (decoder, OpenCV, a bug) must not stop the batch
        first = (str(e).splitlines() or [""])[0]
        record.update(status="failed", reason=f"{source.path}: {type(e).__name__}: {first}")
    else:
        split = split_for(source.key)
        record["crops"] = [_write_crop(out, source, c, i, split) for i, c in enumerate(crops)]
        record.update(status="done" if crops else "empty", reason="" if crops else "no object found")
    write_json(out / RECORDS / f"{source.key}.json", record)
    return record


def _work(args: tuple) -> dict:
    return process_source(*args)


def _init_worker() -> None:
    cv2.setNumThreads(1)


def _run(jobs: list[tuple], workers: int) -> Iterator[dict]:
    if workers <= 1 or len(jobs) <= 1:
        yield from map(_work, jobs)
        return
    # spawn, not fork: a parent that already ran OpenCV or torch thread pools can leave forked children deadlocked
    with multiprocessing.get_context("spawn").Pool(workers, initializer=_init_worker) as pool:
        yield from pool.imap_unordered(_work, jobs)


@dataclass
class Summary:
    """What a `radar masks` run did (the CLI prints it; it is also saved as summary.json)."""

    photos: int = 0
    skipped_done: int = 0
    failed: int = 0
    no_object: int = 0
    accepted: dict = field(default_factory=dict)
    rejected: int = 0
    reasons: dict = field(default_factory=dict)
    seconds: float = 0.0
    photos_per_second: float = 0.0
    sheets: list = field(default_factory=list)


def prepare(data_dir: str | Path, out: str | Path, settings: Settings = Settings(), workers: int = 1,
            spec: DetectorSpec = DetectorSpec(), contact_sheet: bool = True, progress: bool = True) -> Summary:
    """Turn a folder of photographs into training crops; resumable (finished photos are skipped).

    Returns:
        The run's Summary over all records (this run's and earlier ones').

    Raises:
        InputError: `out` is `data_dir`; NothingToDoError: `data_dir` holds no photograph (nothing is written).
    """
    out = Path(out)
    if out.resolve() == Path(data_dir).resolve():
        raise InputError(f"{out}: --out is the photo folder; choose a dataset folder outside it")
    sources = list_sources(data_dir, exclude=out)
    if not sources:
        raise NothingToDoError(f"{data_dir}: no photographs ({', '.join(PHOTO_EXTENSIONS)})")
    if out.is_dir():
        remove_stale_temps(out, recursive=True)  # what a killed run was writing
    if spec.name == "onnx":
        _detector(spec)  # fail early, in this process, on a missing runtime or a bad model
    done = {p.stem for p in (out / RECORDS).glob("*.json")}
    jobs = [(out, s, settings, spec) for s in sources if s.key not in done]
    t0 = time.perf_counter()
    for record in tqdm(_run(jobs, workers), total=len(jobs), desc="masks", unit="photo", disable=not progress):
        if record["status"] == "failed":
            tqdm.write(record["reason"], file=sys.stderr)
    elapsed = time.perf_counter() - t0
    records = [json.loads(p.read_text()) for p in sorted((out / RECORDS).glob("*.json"))]
    summary = _summarise(records, len(sources) - len(jobs), elapsed, len(jobs))
    _write_tables(out, records)
    if contact_sheet:
        crops = [c for r in records for c in r["crops"]]
        summary.sheets = [str(p) for p in write_sheets(crops, out, out / "contact_sheet")] if crops else []
    write_json(out / "summary.json", asdict(summary))
    return summary


def _summarise(records: list[dict], skipped: int, elapsed: float, processed: int) -> Summary:
    s = Summary(photos=len(records), skipped_done=skipped, seconds=round(elapsed, 2))
    s.photos_per_second = round(processed / elapsed, 2) if elapsed > 0 else 0.0
    reasons: Counter[str] = Counter()
    accepted: Counter[str] = Counter()
    for r in records:
        s.failed += r["status"] == "failed"
        s.no_object += r["status"] == "empty"
        for c in r["crops"]:
            if c["accepted"]:
                accepted[c["split"]] += 1
            else:
                s.rejected += 1
                reasons.update(reason.split(" ")[0].rstrip(":") for reason in c["reasons"])
    s.accepted, s.reasons = dict(accepted), dict(reasons)
    return s


def _write_tables(out: Path, records: list[dict]) -> None:
    """rejected.csv (crop id, source, reasons) and failures.csv (source, problem)."""
    rej, fail = io.StringIO(), io.StringIO()
    rw, fw = csv.writer(rej), csv.writer(fail)
    rw.writerow(["id", "source", "reasons"])
    fw.writerow(["source", "problem"])
    for r in records:
        if r["status"] in ("failed", "empty"):
            fw.writerow([r["source"], r["reason"]])
        for c in r["crops"]:
            if not c["accepted"]:
                rw.writerow([c["id"], r["source"], "; ".join(c["reasons"])])
    write_text(out / "rejected.csv", rej.getvalue())
    write_text(out / "failures.csv", fail.getvalue())
