"""The tests' own Met records have the schema of the API's recorded responses (checked when those are present)."""

from __future__ import annotations

import json

import pytest

from . import met_records
from .conftest import DEPARTMENTS, TEMPLATES


def _kind(value) -> str:
    return "null" if value is None else type(value).__name__


@pytest.mark.parametrize("kind", met_records.KINDS)
def test_built_records_have_the_recorded_keys_and_types(kind, shared_data) -> None:
    recorded = json.loads((shared_data("data", "met_api") / TEMPLATES[kind]).read_text(encoding="utf-8"))
    built = met_records.object_record(kind, recorded["objectID"])
    assert set(recorded) <= set(built)  # newer records add keys (measurements, GalleryNumber)
    assert {k: _kind(v) for k, v in recorded.items()} == {k: _kind(built[k]) for k in recorded}
    assert bool(built["primaryImage"]) == bool(recorded["primaryImage"]) == recorded["isPublicDomain"]


def test_built_departments_match_the_recorded_ids(shared_data) -> None:
    recorded = json.loads((shared_data("data", "met_api") / DEPARTMENTS).read_text(encoding="utf-8"))["departments"]
    assert [d["departmentId"] for d in met_records.departments()] == [d["departmentId"] for d in recorded]


def test_record_kinds() -> None:
    scroll, cover, not_pd = (met_records.object_record(k, 7) for k in met_records.KINDS)
    assert scroll["objectID"] == 7 and scroll["isPublicDomain"] and len(scroll["additionalImages"]) == 2
    assert cover["additionalImages"] == [] and cover["constituents"] is None and cover["tags"] is None
    assert not not_pd["isPublicDomain"] and not_pd["primaryImage"] == not_pd["primaryImageSmall"] == ""
    with pytest.raises(ValueError):
        met_records.object_record("statue")
