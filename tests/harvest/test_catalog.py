"""The SQLite catalog: states, pending work, changed records, attribution reads."""

from __future__ import annotations

import pytest

from radar_cli.errors import InputError
from radar_cli.harvest.catalog import iter_images, open_catalog

RECORD = {"objectID": 5, "isPublicDomain": True, "title": "Vase", "objectName": "Vase", "creditLine": "Gift",
          "objectURL": "https://www.metmuseum.org/art/collection/search/5", "department": "Asian Art"}


def test_states_move_through_the_pipeline(tmp_path):
    with open_catalog(tmp_path) as catalog:
        assert catalog.db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        assert catalog.add_searched([5, 3, 9]) == 3 and catalog.add_searched([9, 4]) == 1  # known ids kept
        assert catalog.pending_records() == [5, 3, 9, 4]  # search order
        catalog.set_record(5, RECORD, "met/5.json", "http://img/5.jpg", "record")
        catalog.set_state(3, "skipped", "not_found")
        catalog.set_state(9, "failed", "HTTP 503")
        assert catalog.pending_records() == [9, 4] and catalog.pending_images() == [5]
        catalog.set_image(5, "met/5.jpg", 123, "ab" * 32, '"e1"')
        assert catalog.counts() == {"searched": 1, "record": 0, "image": 1, "skipped": 1, "failed": 1}
        assert dict(catalog.skip_reasons()) == {"not_found": 1}
        row = catalog.get(5)
        assert (row["licence"], row["credit_line"], row["bytes"]) == ("CC0-1.0", "Gift", 123)


def test_changed_record_is_refetched_with_image_facts_kept(tmp_path):
    with open_catalog(tmp_path) as catalog:
        catalog.add_searched([5])
        catalog.set_record(5, RECORD, "met/5.json", "http://img/5.jpg", "record")
        catalog.set_image(5, "met/5.jpg", 123, "ab" * 32, '"e1"')
        assert catalog.mark_changed([5, 77]) == 1
        catalog.set_state(5, "failed", "HTTP 503")
        assert catalog.pending_records() == [5] and catalog.pending_images() == []
        assert catalog.get(5)["etag"] == '"e1"'


def test_iter_images_needs_a_catalog(tmp_path):
    with pytest.raises(InputError, match="no harvest catalog"):
        list(iter_images(tmp_path))


def test_corrupt_catalog_is_an_input_error(tmp_path):
    (tmp_path / "catalog.sqlite").write_bytes(b"this is not sqlite" * 100)
    with pytest.raises(InputError, match="not a usable catalog"):
        open_catalog(tmp_path)
