"""An object's size from its Met record: the structured `measurements` (cm per element) or the catalogue's
`dimensions` text ("H. 8 1/2 in. (21.6 cm); Diam. of rim 5 in. (12.7 cm)", metric or inches first, ranges,
several parts), with the reason when the record gives none or does not say which length is the height."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import Any

from radar_cli.sizes import MAX_CM, ObjectSize

UNITS_CM = {"cm": 1.0, "mm": 0.1, "m": 100.0, "in": 2.54, "inch": 2.54, "inches": 2.54}
NUMBER = r"\d+\s+\d+/\d+|\d+/\d+|\d+(?:\.\d+)?"  # 8 1/2, 3/4, 21.6
QUANTITY = rf"(?:{NUMBER})(?:\s*(?:-|–|—|to)\s*(?:{NUMBER}))?"  # a value or a range
MEASURE = re.compile(rf"(?P<values>{QUANTITY}(?:\s*[x×]\s*{QUANTITY})*)\s*(?P<unit>cm|mm|m|inches|inch|in)\b\.?",
                     re.IGNORECASE)
LABEL = re.compile(r"\b(?P<label>height|ht|h|width|wd|w|diameter|diam|dia|depth|d|length|l)\b\.?",
                   re.IGNORECASE)
KINDS = {"height": "height", "ht": "height", "h": "height", "width": "width", "wd": "width", "w": "width",
         "diameter": "diameter", "diam": "diameter", "dia": "diameter", "depth": "depth", "d": "depth",
         "length": "length", "l": "length"}
DIAMETER_PLACES = {"rim": ("rim", "mouth", "lip", "opening", "neck"), "foot": ("foot", "base"),
                   "body": ("body", "max", "shoulder", "belly", "widest", "greatest")}
AGREE = 0.02  # two sources of one height agree within 2%


@dataclass(frozen=True)
class Measure:
    """One labelled length of a dimensions text: kind (height, width, diameter, depth, length or None when not
    labelled), where it was measured (`of rim`, `with handles`), the part (`Overall`, `Lid`) and cm (lo, hi)."""

    kind: str | None
    place: str
    part: str
    lo: float
    hi: float


def _number(text: str) -> float:
    return float(sum(Fraction(p) for p in text.split()))


def _quantity(text: str, unit: float) -> tuple[float, float]:
    ends = re.split(r"\s*(?:-|–|—|to)\s*", text.strip())
    values = [_number(e) * unit for e in ends if e]
    return min(values), max(values)


def _segment_measures(segment: str) -> list[Measure]:
    """The lengths of one `;`-separated segment; the metric figures win over the converted inches."""
    found = list(MEASURE.finditer(segment))
    if not found:
        return []
    metric = [m for m in found if m["unit"].lower() in ("cm", "mm", "m")]
    best = (metric or found)[0]
    unit = UNITS_CM[best["unit"].lower()]
    values = [_quantity(v, unit) for v in re.split(r"\s*[x×]\s*", best["values"])]
    prefix = segment[: found[0].start()]
    labels = list(LABEL.finditer(prefix))
    part = (prefix[: labels[0].start()] if labels else prefix).strip(" :,.()").strip()
    place = prefix[labels[-1].end():].strip(" :,.()").lower() if labels else ""
    kinds: list[str | None] = [KINDS[m["label"].lower()] for m in labels]
    if len(kinds) == 1 and "max" in prefix.lower() and kinds[0] == "diameter":
        place = place or "max"
    if len(kinds) != len(values):  # unlabelled "46 5/8 x 18 3/4 in.", or labels that do not match the values
        kinds = [None] * len(values)
    return [Measure(k, place, part, lo, hi) for k, (lo, hi) in zip(kinds, values)]


def parse_dimensions(text: str) -> list[Measure]:
    """Every length of a Met `dimensions` text (segments split at `;` and line breaks)."""
    return [m for seg in re.split(r"[;\r\n]+", text or "") for m in _segment_measures(seg)]


def _cm(value: float) -> float:
    return round(value, 2)


def _one(measures: list[Measure], what: str) -> tuple[float | None, str]:
    """The one length of a kind: the `Overall` part's if any, unqualified before qualified; a range gives its
    larger end. Returns (cm or None, note); None with a note when several different ones remain."""
    if not measures:
        return None, ""
    overall = [m for m in measures if "overall" in m.part.lower()]
    pool = overall or measures
    plain = [m for m in pool if not m.place and not m.part] or [m for m in pool if not m.place] or pool
    values = sorted({_cm(m.hi) for m in plain})
    if len(values) > 1 and values[-1] > values[0] * (1 + AGREE):
        labels = ", ".join(f"{' '.join(filter(None, (m.part, what, m.place)))} {_cm(m.hi):g} cm" for m in plain)
        return None, f"several {what}s ({labels})"
    chosen = max(plain, key=lambda m: m.hi)
    notes = []
    if chosen.hi > chosen.lo:
        notes.append(f"{what} given as {_cm(chosen.lo):g}-{_cm(chosen.hi):g} cm: the larger used")
    if chosen.place:
        notes.append(f"{what} {chosen.place}")
    return _cm(chosen.hi), "; ".join(notes)


def _diameters(measures: list[Measure]) -> dict[str, float | None]:
    found: dict[str, float | None] = {"rim_cm": None, "body_cm": None, "foot_cm": None, "diameter_cm": None}
    for m in measures:
        if m.kind != "diameter":
            continue
        where = next((k for k, words in DIAMETER_PLACES.items() if any(w in m.place for w in words)), "diameter")
        key = f"{where}_cm"
        if found[key] is None:
            found[key] = _cm(m.hi)
    return found


def size_from_dimensions(text: str) -> ObjectSize:
    """The size a `dimensions` text gives (status `none` or `ambiguous` with a note when it gives no height)."""
    if not (text or "").strip():
        return ObjectSize(status="none", source="met record dimensions", note="no dimensions given")
    measures = parse_dimensions(text)
    if not measures:
        return ObjectSize(status="none", source="met record dimensions", note=f"no length in {text.strip()!r}")
    height, note = _one([m for m in measures if m.kind == "height"], "height")
    width, _ = _one([m for m in measures if m.kind == "width"], "width")
    if height is None:
        unlabelled = [m for m in measures if m.kind is None]
        why = note or (f"unlabelled lengths ({' x '.join(f'{_cm(m.hi):g}' for m in unlabelled)} cm): which is the "
                       "height is not said" if unlabelled else "no height given")
        return ObjectSize(width_cm=width, **_diameters(measures), status="ambiguous" if note or unlabelled else "none",
                          source="met record dimensions", note=why)
    return ObjectSize(height_cm=height, width_cm=width, **_diameters(measures), status="ok",
                      source="met record dimensions", note=note)


def _positive(value: Any) -> float | None:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    return _cm(float(value)) if ok and 0 < value < MAX_CM else None


def size_from_measurements(measurements: Any) -> ObjectSize:
    """The size the structured `measurements` give (elementMeasurements in cm): the `Overall` element, or the
    only element with a height."""
    elements = [e for e in measurements if isinstance(e, dict)] if isinstance(measurements, list) else []
    sized = [e for e in elements if isinstance(e.get("elementMeasurements"), dict)
             and _positive(e["elementMeasurements"].get("Height")) is not None]
    source = "met record measurements"
    if not sized:
        return ObjectSize(status="none", source=source, note="no height in the measurements")
    overall = [e for e in sized if str(e.get("elementName") or "").strip().lower() == "overall"]
    heights = {_positive(e["elementMeasurements"]["Height"]) for e in overall or sized}
    if len(overall or sized) > 1 and len(heights) > 1:
        names = ", ".join(f"{e.get('elementName')} {_positive(e['elementMeasurements']['Height']):g} cm"
                          for e in overall or sized)
        return ObjectSize(status="ambiguous", source=source, note=f"several heights ({names})")
    element = (overall or sized)[0]
    values = element["elementMeasurements"]
    description = str(element.get("elementDescription") or "").strip()
    return ObjectSize(height_cm=_positive(values.get("Height")), diameter_cm=_positive(values.get("Diameter")),
                      width_cm=_positive(values.get("Width")), status="ok", source=source,
                      note=description[:200])


def size_of_record(record: dict[str, Any]) -> ObjectSize:
    """An object record's size: the measurements' height, with the text's rim, body and foot diameters where
    its height agrees; else the dimensions text's; else why there is none."""
    structured = size_from_measurements(record.get("measurements"))
    text = size_from_dimensions(str(record.get("dimensions") or ""))
    if not structured.known:
        if text.known or structured.status == "none":
            return text
        return replace(text, note="; ".join(filter(None, (text.note, "measurements: " + structured.note))))
    if text.known and abs(text.height_cm - structured.height_cm) <= AGREE * structured.height_cm:  # type: ignore
        return replace(structured, rim_cm=text.rim_cm, body_cm=text.body_cm, foot_cm=text.foot_cm,
                       diameter_cm=structured.diameter_cm or text.diameter_cm, width_cm=structured.width_cm
                       or text.width_cm)
    return structured
