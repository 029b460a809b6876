"""What a museum's own record calls an object, read for what radar cannot rebuild: a fragment, a vessel made as
a head or figure, a lid or stand on its own. A search of a collection for "vase" returns all of these beside whole
vessels (the Met's titles: "Terracotta fragment of a kylix", "Glass double head-shaped flask", "Terracotta head
vase", "Porcelain cover"); a photograph may not show it (a head worn smooth, a sherd's straight break), the
record says it in words.
"""

from __future__ import annotations

import re

KINDS: tuple[tuple[str, re.Pattern[str]], ...] = (
    ("a fragment", re.compile(r"\b(fragments?|fragmentary|sherds?|shards?|potsherds?|ostrak(a|on))\b")),
    ("a head or figure, or a vessel made as one", re.compile(
        r"\bhead[- ](shaped|vases?|flasks?|jugs?|bottles?|cups?|kantharos|aryballos)\b|\bjani(form|us)\b"
        r"|^\W*(\w+ ){0,2}heads? of\b"
        r"|\b(plastic|figural|figure|figured) vases?\b|\bfigurines?\b|\bstatuettes?\b|\brhyta|\brhyton\b"
        r"|\b(in the (form|shape) of|shaped (as|like)) an? \w+")),
    ("a lid or stand on its own", re.compile(
        r"^\W*((?!with\b|and\b|without\b)\w+ ){0,2}(lids?|covers?|stoppers?|stands?)\b(\s+(of|for)\b|\s*[,(]|$)")),
)
"""The kinds and the words that name them, matched in lower case; a lid or stand only where it is the title's
subject ("Lid of a pyxis", "Bronze stand"), not a vessel's part ("Pyxis with lid")."""


def not_a_whole_vessel(description: str) -> str | None:
    """The kind of object a catalogue description (a title, an object name) names, where that is not one whole
    turned vessel (`KINDS`), else None."""
    text = " ".join(description.casefold().split())
    for kind, words in KINDS:
        if words.search(text):
            return kind
    return None
