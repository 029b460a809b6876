"""What a catalogue's title calls an object: fragments, heads and figures, lids and stands on their own are named;
whole vessels, and vessels with a head painted on them or a lid on them, are not."""

from __future__ import annotations

import pytest

from radar_cli.catalogue_terms import not_a_whole_vessel


@pytest.mark.parametrize("title,kind", [
    ("Terracotta fragment of a kylix (drinking cup)", "a fragment"),
    ("Fragments of a terracotta amphora", "a fragment"),
    ("krater fragment", "a fragment"),
    ("Glass double head-shaped flask", "a head or figure, or a vessel made as one"),
    ("Terracotta head vase", "a head or figure, or a vessel made as one"),
    ("Janiform head flask", "a head or figure, or a vessel made as one"),
    ("Terracotta rhyton (vase for libations) in the form of a ram's head", "a head or figure, or a vessel made as one"),
    ("Vase in the shape of a duck", "a head or figure, or a vessel made as one"),
    ("Terracotta statuette of a woman", "a head or figure, or a vessel made as one"),
    ("Limestone head of a man", "a head or figure, or a vessel made as one"),
    ("Lid of a pyxis", "a lid or stand on its own"),
    ("Porcelain cover", "a lid or stand on its own"),
    ("Bronze stand", "a lid or stand on its own"),
    ("Stand for a dinos", "a lid or stand on its own"),
])
def test_what_is_not_a_whole_vessel_is_named(title, kind):
    assert not_a_whole_vessel(title) == kind


@pytest.mark.parametrize("title", [
    "Terracotta column-krater (bowl for mixing wine and water)",
    "Terracotta oinochoe: chous (jug)",
    "Storage jar with the Orsini arms and the profile head of a man",
    "Storage jar (Albarello) with profile portrait",
    "Terracotta canopic urn",
    "Terracotta pyxis with lid",
    "Vase with cover",
    "Covered jar",
    "  TERRACOTTA   LEKYTHOS  ",
    "",
])
def test_whole_vessels_are_not_named(title):
    assert not_a_whole_vessel(title) is None
