"""End-to-end harvests against the fake Met server: every injected fault ends in the right catalog state."""

from __future__ import annotations

import csv
import dataclasses
import json
import os

import pytest

from radar_cli.errors import InputError
from radar_cli.harvest import harvester as harvester_module
from radar_cli.harvest.catalog import iter_images, open_catalog
from radar_cli.harvest.harvester import harvest

RECORD_FAULTS = {2: ("429",), 3: ("500", "503"), 4: ("slow",), 5: ("truncated",), 6: ("html403",),
                 7: ("html200",), 8: ("malformed",), 16: ("503",) * 4}  # FAST retries 3: four attempts, all 503
IMAGE_FAULTS = {17: ("500", "html403"), 18: ("truncated", "html200", "429")}
EXPECTED = {
    **{i: ("image", "") for i in (1, 2, 3, 4, 5, 6, 7, 8, 17, 18)},
    9: ("skipped", "not_found"),
    10: ("skipped", "not_public_domain"),
    11: ("skipped", "no_image"),
    12: ("failed", "corrupt image"),
    13: ("skipped", "image_too_large"),
    14: ("skipped", "image_too_large"),
    15: ("skipped", "image_missing"),
    16: ("failed", "HTTP 503"),
}


@pytest.fixture
def faulty(met_server, bomb):
    """Objects 1..18, one fault each (see EXPECTED)."""
    for i in range(1, 19):
        met_server.add(i)
    met_server.add(10, kind="not_pd")
    met_server.add(11, primaryImage="", primaryImageSmall="")
    met_server.withdrawn.add(9)
    met_server.images[12] = met_server.images[12][:-200]  # a corrupt (truncated) JPEG
    met_server.images[13] = bomb  # decodes to 144 Mpx
    met_server.images[14] = os.urandom(1_200_000)  # over the 1 MB test limit
    del met_server.images[15]  # the image host answers an HTML 404
    for i, faults in RECORD_FAULTS.items():
        met_server.fault(f"/api/v1/objects/{i}", *faults)
    for i, faults in IMAGE_FAULTS.items():
        met_server.fault(f"/images/{i}.jpg", *faults)
    return met_server


@pytest.fixture(scope="session")
def bomb():
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.new("1", (12_000, 12_000)).save(buf, format="PNG")
    return buf.getvalue()


def states(out) -> dict[int, tuple[str, str]]:
    with open_catalog(out) as catalog:
        return {r["object_id"]: (r["state"], r["reason"]) for r in catalog.rows()}


def test_every_fault_ends_in_the_right_state(faulty, harvest_config):
    config = harvest_config()
    summary = harvest(config)
    got = states(config.out)
    assert set(got) == set(EXPECTED)
    for object_id, (state, reason) in EXPECTED.items():
        assert got[object_id][0] == state, (object_id, got[object_id])
        assert reason in got[object_id][1], (object_id, got[object_id])
    assert summary.found == 18 and summary.images_fetched == 10 and summary.failed == 2
    assert dict(summary.skipped) == {"not_found": 1, "not_public_domain": 1, "no_image": 1,
                                     "image_too_large": 2, "image_missing": 1}
    assert "found 18, fetched 10 images" in summary.line() and "failed 2" in summary.line()
    with open(config.out / "failures.csv", newline="") as f:
        assert [int(r["object_id"]) for r in csv.DictReader(f)] == [12, 16]
    # records verbatim, images under numeric names, nothing else in the folder
    assert (config.out / "met" / "1.json").read_bytes() == faulty.record_body(1)
    names = sorted(p.name for p in (config.out / "met").iterdir())
    images = sorted(f"{i}.jpg" for i, (s, _) in EXPECTED.items() if s == "image")
    records = sorted(f"{i}.json" for i in EXPECTED if i not in (9, 16))
    assert names == sorted(images + records)


def test_rerun_retries_failures_and_remembers_404s(faulty, harvest_config):
    config = harvest_config()
    harvest(config)
    summary = harvest(config)  # 16's record now loads; 12's image is still corrupt
    got = states(config.out)
    assert got[16] == ("image", "") and got[12][0] == "failed" and summary.failed == 1
    assert faulty.hits("/api/v1/objects/9") == 1  # negative cache: the withdrawn object is not asked again
    assert faulty.hits("/api/v1/objects/1") == 1 and faulty.hits("/images/1.jpg") == 1


def test_since_refetches_only_changed_records(met_server, harvest_config):
    for i in range(1, 5):
        met_server.add(i, metadataDate="2020-01-01T00:00:00.000Z")
    config = harvest_config()
    harvest(config)
    met_server.objects[2].update(title="Renamed vase", metadataDate="2026-11-01T00:00:00.000Z")
    met_server.objects[3].update(isPublicDomain=False, metadataDate="2026-11-02T00:00:00.000Z")
    summary = harvest(dataclasses.replace(config, since="2026-10-01"))
    assert [met_server.hits(f"/api/v1/objects/{i}") for i in range(1, 5)] == [1, 2, 2, 1]
    assert summary.records_fetched == 2 and summary.images_unchanged == 1 and summary.images_fetched == 0
    titles = {e.object_id: e.title for e in iter_images(config.out)}
    assert titles[2] == "Renamed vase" and sorted(titles) == [1, 2, 4]
    assert states(config.out)[3] == ("skipped", "not_public_domain")
    assert not (config.out / "met" / "3.jpg").exists()  # no longer public domain: its image is removed


def test_ids_file_limit_small_images_and_all(met_server, harvest_config, tmp_path):
    met_server.add(1)
    met_server.add(2, kind="not_pd", primaryImage=f"{met_server.url}/images/2.jpg",
                   primaryImageSmall=f"{met_server.url}/images/2-small.jpg")
    met_server.add(3)
    ids = tmp_path / "ids.txt"
    ids.write_text("# wanted\n2\n1\n\n3\n")
    config = harvest_config(ids_file=ids, limit=2, public_domain_only=False, image="small")
    summary = harvest(config)
    assert summary.found == 2 and states(config.out) == {2: ("image", ""), 1: ("image", "")}
    assert met_server.hits("/api/v1.1/search") == 0 and met_server.hits("/images/2-small.jpg") == 1
    licences = {e.object_id: e.licence for e in iter_images(config.out)}
    assert licences == {2: "not public domain", 1: "CC0-1.0"}


def test_iter_images_gives_attribution(met_server, harvest_config):
    record = met_server.add(45734)
    config = harvest_config()
    harvest(config)
    (entry,) = list(iter_images(config.out))
    assert entry.image_path == config.out / "met" / "45734.jpg" and entry.image_path.is_file()
    assert (entry.title, entry.credit_line) == (record["title"], record["creditLine"])
    assert entry.object_url == record["objectURL"] and entry.licence == "CC0-1.0"
    with open_catalog(config.out) as catalog:
        row = catalog.get(45734)
    assert row["classification"] == "Paintings" and row["department"] == "Asian Art"
    assert row["bytes"] == entry.image_path.stat().st_size and len(row["sha256"]) == 64 and row["etag"]
    assert json.loads((config.out / row["record_path"]).read_text())["objectID"] == 45734


def test_ctrl_c_stops_cleanly_and_resumes(met_server, harvest_config, monkeypatch):
    for i in range(1, 6):
        met_server.add(i)
    original = harvester_module.Harvester._image
    calls = []

    def interrupted(self, object_id):
        calls.append(object_id)
        if len(calls) == 3:
            raise KeyboardInterrupt
        original(self, object_id)

    monkeypatch.setattr(harvester_module.Harvester, "_image", interrupted)
    config = harvest_config()
    summary = harvest(config)
    assert summary.interrupted and summary.counts["image"] == 2 and summary.counts["record"] == 3
    assert "interrupted" in summary.line()
    monkeypatch.setattr(harvester_module.Harvester, "_image", original)
    assert harvest(config).counts["image"] == 5


def test_outage_stops_the_run(met_server, harvest_config, monkeypatch):
    monkeypatch.setattr(harvester_module, "MAX_CONSECUTIVE_FAILURES", 3)
    for i in range(1, 8):
        met_server.add(i)
        met_server.fault(f"/api/v1/objects/{i}", *["503"] * 10)
    summary = harvest(harvest_config())
    assert "3 objects failed in a row" in summary.aborted
    assert summary.counts["failed"] == 3 and summary.counts["searched"] == 4


def test_one_run_per_folder(met_server, harvest_config):
    import fcntl

    config = harvest_config()
    config.out.mkdir(parents=True)
    with open(config.out / ".fetch.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(InputError, match="another `radar fetch` is writing"):
            harvest(config)
    met_server.add(1)
    assert harvest(config).counts["image"] == 1
