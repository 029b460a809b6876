"""Real size: a dimensions table or a harvested record's size puts the meshes in metres at the catalogue's height
(read back with trimesh), material.json and the gallery say so, and objects without a size stay unitless."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import trimesh
from click.testing import CliRunner

from radar_cli.cli import cli
from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.inputs import InputItem
from radar_cli.derender.run.object_record import ObjectRecord, RecordFinder
from radar_cli.errors import InputError
from radar_cli.harvest.catalog import open_catalog
from radar_cli.sizes import read_size_table

from .conftest import SIZE, write_photo
from .test_gallery import gallery_data

EXPORT = ExportConfig(views=0, view_size=32)
# the columns of a catalogue table such as ../shared/data/cva10/objects.tsv, fragments without a height
TABLE = ("object\taccession\tkind\theight_cm\trim_cm\tbody_cm\tfoot_cm\twidth_with_handles_cm\n"
         "73AE135\t73.AE.135\twhole\t35\t30\t29\t16\t34.5\n"
         "81AE161\t81.AE.161\twhole\t31\t26\t23.25\t12.9\t30.4\n"
         "86AE203\t86.AE.203\tfragment\t\t\t\t\t\n")


def glb_height(folder: Path) -> float:
    """The height of mesh.glb in its file's units (metres when sized)."""
    scene = trimesh.load(folder / "mesh.glb")
    return float(scene.bounds[1][1] - scene.bounds[0][1])


def glb_height_cm(folder: Path) -> float:
    return glb_height(folder) * 100.0


def material(folder: Path) -> dict:
    return json.loads((folder / "material.json").read_text())


def test_table_gives_meshes_at_the_catalogue_height(tmp_path, predictor):
    write_photo(tmp_path / "in" / "73AE135" / "front.png", 1)  # matched by its folder
    write_photo(tmp_path / "in" / "81AE161_back.png", 2)  # matched as <id>_<view>
    write_photo(tmp_path / "in" / "other.png", 3)
    table = tmp_path / "objects.tsv"
    table.write_text(TABLE)
    out = tmp_path / "out"
    summary = derender([tmp_path / "in"], predictor,
                       DerenderOptions(out=out, export=EXPORT, resolution=SIZE, dimensions=table))
    assert sorted(summary.done) == ["81AE161_back", "front", "other"] and not summary.failures
    for name, height in (("front", 35.0), ("81AE161_back", 31.0)):
        assert glb_height_cm(out / name) == pytest.approx(height, rel=0.01)
        rec = material(out / name)
        assert rec["size_cm"]["height"] == height and rec["size_source"] == "table objects.tsv"
        assert rec["mesh_unit"] == "m" and rec["mesh_cm"]["height"] == pytest.approx(height, rel=1e-3)
        obj = trimesh.load(out / name / "mesh.obj", force="mesh")
        assert float(obj.extents[1]) * 100 == pytest.approx(height, rel=0.01)
    assert material(out / "front")["size_cm"] == {"height": 35.0, "rim": 30.0, "body": 29.0, "foot": 16.0}
    unitless = material(out / "other")
    assert not {"size_cm", "mesh_unit", "size_source"} & set(unitless)
    assert glb_height(out / "other") < 3.0  # model units (the sized ones are 0.31-0.35 m)
    objects = {o["id"]: o for o in gallery_data(out)["objects"]}
    assert objects["front"]["size"]["cm"]["height"] == 35.0 and objects["other"]["size"] is None


def test_harvested_size_for_a_primary_image_and_a_view(tmp_path, predictor):
    data = tmp_path / "data"
    with open_catalog(data) as catalog:
        catalog.add_searched([5, 6, 7])
        for object_id, dims in ((5, "H. 8 1/2 in. (21.6 cm); Diam. 5 in. (12.7 cm)"),
                                (6, "H. 30 cm"), (7, "46 5/8 x 18 3/4 in. (118.4 x 47.6 cm)")):
            catalog.set_record(object_id, {"objectID": object_id, "isPublicDomain": True, "dimensions": dims},
                               f"met/{object_id}.json", f"https://x/{object_id}.jpg", "record")
        catalog.set_image(5, "met/5.jpg", 1, "", "")
        catalog.set_image(6, "met/6/6_0.jpg", 1, "", "")
        catalog.sync_views(6, ["https://x/6b.jpg"])
        catalog.set_view(6, 1, "image", image_path="met/6/6_1.jpg", size=1, sha256="", etag="")
        catalog.set_image(7, "met/7.jpg", 1, "", "")
    write_photo(data / "met" / "5.jpg", 4)
    write_photo(data / "met" / "6" / "6_1.jpg", 5)
    write_photo(data / "met" / "7.jpg", 6)
    out = tmp_path / "out"
    derender([data / "met"], predictor, DerenderOptions(out=out, export=EXPORT, resolution=SIZE))
    assert glb_height_cm(out / "5") == pytest.approx(21.6, rel=0.01)
    assert glb_height_cm(out / "6_1") == pytest.approx(30.0, rel=0.01)
    assert material(out / "5")["size_source"] == "met record dimensions"
    ambiguous = material(out / "7")
    assert ambiguous["size_note"].startswith("ambiguous: unlabelled") and "mesh_unit" not in ambiguous
    assert glb_height(out / "7") > 0.5  # model units: 118.4 or 47.6 cm would be 1.18 or 0.48 m


def test_table_is_read_strictly(tmp_path):
    path = tmp_path / "sizes.csv"
    path.write_text("id,height_cm,rim_cm\nA,12.5,\nB,abc,3\n")
    with pytest.raises(InputError, match=r"sizes.csv:3: height_cm 'abc' is not a number"):
        read_size_table(path)
    path.write_text("id,height_cm\nA,12\na,13\n")
    with pytest.raises(InputError, match="given twice"):
        read_size_table(path)
    path.write_text("name,height\nA,12\n")
    with pytest.raises(InputError, match="no object id column"):
        read_size_table(path)
    path.write_text("id,height\nA,12\n")
    with pytest.raises(InputError, match=r"sizes.csv: no height_cm column \(nor title, object_name"):
        read_size_table(path)
    path.write_text("id,title\nA,Terracotta head vase\n")  # a table of titles alone describes, sizes nothing
    titles = read_size_table(path)
    assert titles.lookup("A") is None and titles.describe("A_front") == "Terracotta head vase"
    path.write_text("id,height_cm,rim_cm\nA,12.5,\nA_1,20,4\n")
    table = read_size_table(path)
    assert table.lookup("a").height_cm == 12.5 and table.lookup("A_1_front").height_cm == 20  # longest id
    assert table.lookup("A_2").height_cm == 12.5 and table.lookup("B") is None
    assert table.lookup("front", Path("photos/A/front.jpg")).height_cm == 12.5


def test_cli_dimensions_bad_table_is_one_line(tmp_path, fake_checkpoint):
    write_photo(tmp_path / "in" / "a.png", 1)
    table = tmp_path / "sizes.csv"
    table.write_text("object,height_cm\na,-3\n")
    result = CliRunner().invoke(cli, ["derender", str(tmp_path / "in"), "--out", str(tmp_path / "out"),
                                      "--views", "0", "--dimensions", str(table)])
    assert result.exit_code != 0 and "sizes.csv:2: height_cm '-3' is not a length in cm" in result.output
    table.write_text("object,height_cm\na,20\n")
    result = CliRunner().invoke(cli, ["derender", str(tmp_path / "in"), "--out", str(tmp_path / "out"),
                                      "--views", "0", "--view-size", "32", "--dimensions", str(table)])
    assert result.exit_code == 0, result.output
    assert glb_height_cm(tmp_path / "out" / "a") == pytest.approx(20.0, rel=0.01)


def test_a_harvested_fragment_is_sent_to_review_by_its_title(tmp_path, predictor):
    """The record's title says what the photograph may not show: a fragment is `review` with the catalogue's
    words; a whole vessel's title adds nothing."""
    data = tmp_path / "data"
    with open_catalog(data) as catalog:
        catalog.add_searched([8, 9])
        for object_id, title in ((8, "Terracotta fragment of a kylix (drinking cup)"),
                                 (9, "Terracotta oinochoe: chous (jug)")):
            catalog.set_record(object_id, {"objectID": object_id, "isPublicDomain": True, "title": title,
                                           "objectName": "Kylix fragment" if object_id == 8 else "Chous"},
                               f"met/{object_id}.json", f"https://x/{object_id}.jpg", "record")
            catalog.set_image(object_id, f"met/{object_id}.jpg", 1, "", "")
            write_photo(data / "met" / f"{object_id}.jpg", object_id)
    out = tmp_path / "out"
    derender([data / "met"], predictor, DerenderOptions(out=out, export=EXPORT, resolution=SIZE))
    fragment, jug = material(out / "8")["quality"], material(out / "9")["quality"]
    assert fragment["status"] == "review" and fragment["catalogue_kind"] == "a fragment"
    assert ("the catalogue calls it 'Terracotta fragment of a kylix (drinking cup) / Kylix fragment': a fragment, "
            "not one whole turned vessel") in fragment["reasons"]
    assert "catalogue_kind" not in jug and not any("catalogue" in r for r in jug["reasons"])


def test_a_crop_from_radar_masks_is_described_by_its_meta(tmp_path):
    """A crop `radar masks` wrote carries its record's title in meta.json; a broken one is ignored."""
    photo = tmp_path / "met_5" / "image.png"
    write_photo(photo, 1)
    meta = photo.parent / "meta.json"
    meta.write_text(json.dumps({"attribution": {"title": "Glass double head-shaped flask",
                                                "size": {"height_cm": 9.5, "status": "ok"}}}))
    with RecordFinder() as records:
        found = records.find(InputItem("met_5", photo))
        assert found.description == "Glass double head-shaped flask" and found.size.height_cm == 9.5
        meta.write_text("{not json")
        assert records.find(InputItem("met_5", photo)) == ObjectRecord()


def test_a_table_row_without_a_size_still_describes_its_object(tmp_path, predictor):
    """A catalogue table's fragment (no height, kind `fragment`) gives no size but its description: the result
    is `review` in the catalogue's words; a whole vessel's row adds no such reason."""
    write_photo(tmp_path / "in" / "86AE203_front.png", 1)
    write_photo(tmp_path / "in" / "73AE135_front.png", 2)
    table = tmp_path / "objects.tsv"
    table.write_text(TABLE.replace("\tkind\t", "\tkind\tshape\t").replace("\twhole\t", "\twhole\tcolumn-krater\t")
                     .replace("\tfragment\t", "\tfragment\tkrater fragment\t"))
    assert read_size_table(table).describe("86AE203_front") == "fragment / krater fragment"
    out = tmp_path / "out"
    derender([tmp_path / "in"], predictor, DerenderOptions(out=out, export=EXPORT, resolution=SIZE, dimensions=table))
    fragment, whole = material(out / "86AE203_front"), material(out / "73AE135_front")
    assert "size_cm" not in fragment and fragment["quality"]["catalogue_kind"] == "a fragment"
    assert fragment["quality"]["status"] == "review"
    assert whole["size_cm"]["height"] == 35.0 and "catalogue_kind" not in whole["quality"]
