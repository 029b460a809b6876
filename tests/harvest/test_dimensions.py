"""Sizes from Met records: the `dimensions` text in the catalogue's forms and the structured `measurements`."""

from __future__ import annotations

import pytest

from radar_cli.harvest.dimensions import size_from_dimensions, size_from_measurements, size_of_record

# (text, height, {diameter field: cm}) - forms from the recorded responses and the Met's catalogue styles
KNOWN = [
    ("H. 8 1/2 in. (21.6 cm); Diam. 5 in. (12.7 cm)", 21.6, {"diameter_cm": 12.7}),
    ("H. 1 1/8 in. (2.9 cm); Diam. 1 1/8 in. (2.9 cm)", 2.9, {"diameter_cm": 2.9}),  # recorded 47533
    ("H. 21.6 cm (8 1/2 in.); Diam. of rim 12.7 cm (5 in.)", 21.6, {"rim_cm": 12.7}),  # metric first
    ("H. 9 1/2 in. (24.1 cm)\r\nMax. Diam. 6 in. (15.2 cm)\r\nDiam. of foot 3 in. (7.6 cm)", 24.1,
     {"body_cm": 15.2, "foot_cm": 7.6}),  # CRLF between lines, as the API sends them
    ("H. 10 1/4 in. (26 cm); W. 7 in. (17.8 cm)", 26.0, {"width_cm": 17.8}),
    ("H. 9 1/2 in.", 24.13, {}),  # inches only: converted
    ("Height: 35 cm", 35.0, {}),
    ("H. 8 1/2–9 in. (21.6–22.9 cm)", 22.9, {}),  # a range: the larger end
    ("Overall: H. 5 in. (12.7 cm); Lid: H. 2 in. (5.1 cm)", 12.7, {}),  # the overall height
    ("H. with handles 11 in. (27.9 cm); H. 9 1/2 in. (24.1 cm)", 24.1, {}),  # the body's, not with handles
    ("H. x W. x D.: 10 x 5 x 3 in. (25.4 x 12.7 x 7.6 cm)", 25.4, {"width_cm": 12.7}),
    ("H. 3/4 in. (1.9 cm); Diam. of mouth 1/2 in. (1.3 cm)", 1.9, {"rim_cm": 1.3}),
]


@pytest.mark.parametrize("text,height,diameters", KNOWN)
def test_dimensions_text(text, height, diameters):
    size = size_from_dimensions(text)
    assert size.status == "ok" and size.height_cm == pytest.approx(height, abs=0.01), size
    for field, cm in diameters.items():
        assert getattr(size, field) == pytest.approx(cm, abs=0.01), (field, size)
    assert size.source == "met record dimensions"


def test_range_is_said():
    assert "21.6-22.9 cm" in size_from_dimensions("H. 8 1/2–9 in. (21.6–22.9 cm)").note


@pytest.mark.parametrize("text,status,why", [
    ("", "none", "no dimensions"),
    ("Dimensions unavailable", "none", "no length"),
    ("Diam. 5 in. (12.7 cm)", "none", "no height"),
    ("46 5/8 x 18 3/4 in. (118.4 x 47.6 cm)", "ambiguous", "unlabelled"),  # recorded 45734
    ("11/16 x 2 7/16 x 2 5/8 in. (1.7 x 6.2 x 6.7 cm); 2 dwt. (28.7 g)", "ambiguous", "unlabelled"),  # 1027
    ("a) H. 5 in. (12.7 cm); b) H. 3 in. (7.6 cm)", "ambiguous", "several heights"),
])
def test_no_height_or_ambiguous_says_why(text, status, why):
    size = size_from_dimensions(text)
    assert size.status == status and size.height_cm is None and not size.known
    assert why in size.note


def test_structured_measurements():
    overall = [{"elementName": "Overall", "elementDescription": None,
                "elementMeasurements": {"Depth": 6.6675, "Height": 1.7463, "Weight": 0.0287, "Width": 6.1913}}]
    size = size_from_measurements(overall)
    assert size.known and size.height_cm == 1.75 and size.width_cm == 6.19 and size.source.endswith("measurements")
    two = [{"elementName": "Bowl", "elementMeasurements": {"Height": 10.0, "Diameter": 20.0}},
           {"elementName": "Lid", "elementMeasurements": {"Height": 4.0}}]
    assert size_from_measurements(two).status == "ambiguous"
    with_overall = two + [{"elementName": "Overall", "elementMeasurements": {"Height": 13.0, "Diameter": 20.3}}]
    assert size_from_measurements(with_overall).height_cm == 13.0
    assert size_from_measurements(None).status == "none"
    assert size_from_measurements([{"elementMeasurements": {"Height": "12"}}]).status == "none"  # not a number


def test_record_prefers_measurements_and_takes_the_texts_diameters_when_they_agree():
    record = {"dimensions": "H. 8 1/2 in. (21.6 cm); Diam. of rim 5 in. (12.7 cm)",
              "measurements": [{"elementName": "Overall", "elementMeasurements": {"Height": 21.59, "Diameter": 14.0}}]}
    size = size_of_record(record)
    assert size.height_cm == 21.59 and size.rim_cm == 12.7 and size.diameter_cm == 14.0
    record["measurements"][0]["elementMeasurements"]["Height"] = 30.0  # disagrees: the text's rim is not used
    assert size_of_record(record).rim_cm is None
    unlabelled = {"dimensions": "11/16 x 2 7/16 x 2 5/8 in. (1.7 x 6.2 x 6.7 cm)",
                  "measurements": [{"elementName": "Overall", "elementMeasurements": {"Height": 1.7463}}]}
    assert size_of_record(unlabelled).height_cm == 1.75
    assert size_of_record({"dimensions": "", "measurements": None}).status == "none"
