"""Met Collection API responses made up by the tests, in the schema of the API's recorded responses.

`/objects/<id>` records carry the API's 57 keys in the API's order (a public-domain object with an image, one
without additional images, and a non-public-domain object without any); `/departments` lists 19 departments; the
block page is the shape of the Imperva (Incapsula) page the API answered with when it blocked a client. The
recorded responses in ../shared/data/met_api, when present, are checked against these (tests/harvest/test_records.py)
and replayed by the fake server as well.
"""

from __future__ import annotations

from typing import Any

DEPARTMENT_COUNT = 19
KINDS = ("pd_scroll", "pd_cover", "not_pd")


def _constituent(name: str, role: str) -> dict[str, Any]:
    return {"constituentID": 100_000 + len(name), "role": role, "name": name,
            "constituentULAN_URL": "http://vocab.getty.edu/page/ulan/500000001",
            "constituentWikidata_URL": "https://www.wikidata.org/wiki/Q1", "gender": ""}


def object_record(kind: str, object_id: int = 1) -> dict[str, Any]:
    """One object record as `/objects/<id>` sends it: `pd_scroll` (public domain, an image and two additional
    ones, constituents and tags), `pd_cover` (public domain, one image, constituents and tags null) or `not_pd`
    (not public domain: empty image fields, tags null)."""
    if kind not in KINDS:
        raise ValueError(f"unknown record kind {kind!r}")
    public = kind != "not_pd"
    image = f"https://images.example.org/original/TEST{object_id}.jpg" if public else ""
    return {
        "objectID": object_id, "isHighlight": False, "accessionNumber": f"10.{object_id}.1",
        "accessionYear": "1910", "isPublicDomain": public,
        "primaryImage": image, "primaryImageSmall": image.replace("/original/", "/web-large/"),
        "additionalImages": [f"https://images.example.org/original/TEST{object_id}_{k}.jpg" for k in (1, 2)]
        if kind == "pd_scroll" else [],
        "constituents": None if kind == "pd_cover" else [_constituent("Test Workshop", "Maker")],
        "department": "Asian Art", "objectName": "Vase", "title": f"Test vase {object_id}", "culture": "China",
        "period": "Qing dynasty (1644\u20131911)", "dynasty": "", "reign": "", "portfolio": "",
        "artistRole": "Maker", "artistPrefix": "", "artistDisplayName": "Test Workshop",
        "artistDisplayBio": "1700\u20131750", "artistSuffix": "", "artistAlphaSort": "Test Workshop",
        "artistNationality": "", "artistBeginDate": "1700", "artistEndDate": "1750", "artistGender": "",
        "artistWikidata_URL": "", "artistULAN_URL": "", "objectDate": "18th century",
        "objectBeginDate": 1700, "objectEndDate": 1799, "medium": "Porcelain", "dimensions": "H. 10 cm",
        "measurements": [{"elementName": "Overall", "elementDescription": None,
                          "elementMeasurements": {"Height": 10.0, "Diameter": 6.0}}],
        "creditLine": "Test collection, 1910", "geographyType": "", "city": "", "state": "", "county": "",
        "country": "", "region": "", "subregion": "", "locale": "", "locus": "", "excavation": "", "river": "",
        "classification": {"pd_scroll": "Paintings", "pd_cover": "Ceramics", "not_pd": ""}[kind],
        "rightsAndReproduction": "", "linkResource": "",
        "metadataDate": "2023-01-01T00:00:00.000Z", "repository": "Metropolitan Museum of Art, New York, NY",
        "objectURL": f"https://www.metmuseum.org/art/collection/search/{object_id}",
        "tags": None if kind != "pd_scroll" else [{"term": "Vases", "AAT_URL": "http://vocab.getty.edu/page/aat/1",
                                                  "Wikidata_URL": "https://www.wikidata.org/wiki/Q1"}],
        "objectWikidata_URL": "", "isTimelineWork": False, "GalleryNumber": "",
    }


def departments() -> list[dict[str, Any]]:
    """The `/departments` list: 19 departments with ids 1..21 (the API skips 2 and 20), as the real one."""
    ids = [k for k in range(1, DEPARTMENT_COUNT + 3) if k not in (2, 20)]
    return [{"departmentId": k, "displayName": f"Test department {k}"} for k in ids]


BLOCK_PAGE = (b'<html style="height:100%"><head><META NAME="ROBOTS" CONTENT="NOINDEX, NOFOLLOW"></head>\n'
              b'<body style="margin:0px;height:100%"><iframe src="/_Incapsula_Resource?CWUDNSAI=1&xinfo=0" '
              b'frameborder=0 width="100%" height="100%">Request unsuccessful. Incapsula incident ID: 0-0</iframe>'
              b'</body></html>\n')
