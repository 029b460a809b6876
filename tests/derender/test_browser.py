"""The gallery in a real browser: Debian's Chromium, headless (software WebGL), driven over the DevTools protocol
by Playwright. The bundled model de-renders the example photos; the page must show their thumbnails, draw the
opened object in 3D (pixels of its texture's colour in the middle of the viewer, the backdrop at its rim), relight
it, and raise no console error and no failed request, served by `radar serve` and opened from disk. A gallery of
1,000 objects must paint in under 3 s.

Skips, saying why, without Chromium or the `playwright` package (`make test-browser` installs both).
RADAR_BROWSER_SHOTS=DIR keeps the screenshots (the ones in docs/ come from here).
"""

from __future__ import annotations

import json
import os
import shutil
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from radar_cli.derender.export.object_folder import ExportConfig
from radar_cli.derender.present.gallery import THUMBNAIL_FILE
from radar_cli.derender.present.report import write_report
from radar_cli.derender.present.server import make_server
from radar_cli.derender.run.batch import DerenderOptions, derender
from radar_cli.derender.run.predictor import Predictor

from .test_multiview_views import derender_pot

pytestmark = pytest.mark.browser
REPO = Path(__file__).resolve().parents[2]
CHROMIUM = os.environ.get("RADAR_CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")
# software WebGL: headless Chromium on a machine without a GPU draws through SwiftShader
CHROMIUM_ARGS = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"]
VIEWER_BACKDROP = np.array([0x30, 0x34, 0x3A])  # model-viewer's background in index.css
OBJECT = "synthetic_vase_0"
FIRST_PAINT_LIMIT_MS = 3000

if CHROMIUM is None:
    pytest.skip("Chromium is not installed (apt-get install chromium, or `make test-browser`)", allow_module_level=True)
sync_api = pytest.importorskip("playwright.sync_api", reason="the `playwright` package is not installed "
                               "(pip install -e '.[browser]', or `make test-browser`)")


class PageWatch:
    """Console errors, uncaught exceptions and failed requests of one page."""

    def __init__(self, page) -> None:
        self.problems: list[str] = []
        page.on("console", lambda m: self.problems.append(f"console {m.type}: {m.text}") if m.type == "error" else None)
        page.on("pageerror", lambda e: self.problems.append(f"page error: {e}"))
        page.on("requestfailed", lambda r: self.problems.append(f"request failed: {r.url} ({r.failure})"))
        page.on("response", lambda r: self.problems.append(f"HTTP {r.status}: {r.url}") if r.status >= 400 else None)


@pytest.fixture(scope="module")
def browser():
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield b
        b.close()


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> Path:
    """The six synthetic example vases de-rendered by the bundled model; one object marked for review by a quality
    record and attributed as if its photo came from `radar masks` (a meta.json beside it)."""
    out = tmp_path_factory.mktemp("browser") / "results"
    sample = out.parent / "prepared" / "test" / "met_1"
    sample.mkdir(parents=True)
    (sample / "meta.json").write_text(json.dumps({"attribution": {
        "object_id": 1, "title": "Storage jar", "credit_line": "Rogers Fund, 1917", "licence": "CC0",
        "object_url": "https://www.metmuseum.org/art/collection/search/1"}}))
    options = DerenderOptions(out=out, export=ExportConfig(views=4, view_size=128))
    synthetic = sorted((REPO / "examples").glob("synthetic_vase_*.png"))
    summary = derender(synthetic, Predictor.from_checkpoint(device="cpu"), options)
    assert len(summary.done) == 6 and not summary.failures
    material = json.loads((out / "synthetic_vase_3" / "material.json").read_text())
    material["quality"] = {"status": "review", "reasons": ["symmetry 0.61 < 0.8"], "silhouette_iou": 0.9,
                           "symmetry": 0.61, "recon_psnr": 21.0, "appendage_fraction": 0.0, "cut_edges": [],
                           "frame_coverage": 0.5}
    material["source"] = str(sample / "image.png")
    (out / "synthetic_vase_3" / "material.json").write_text(json.dumps(material))
    write_report(out, [])
    return out


@pytest.fixture(scope="module")
def served(results: Path):
    server = make_server(results, 0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    yield f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def keep(shot: bytes, name: str) -> np.ndarray:
    """The screenshot as H x W x 3 uint8; saved under RADAR_BROWSER_SHOTS when set."""
    import io

    target = os.environ.get("RADAR_BROWSER_SHOTS")
    if target:
        Path(target).mkdir(parents=True, exist_ok=True)
        (Path(target) / name).write_bytes(shot)
    with Image.open(io.BytesIO(shot)) as im:
        return np.asarray(im.convert("RGB"))


def wait_for_thumbnails(page) -> None:
    page.wait_for_function("[...document.querySelectorAll('#grid img')].every(i => i.complete && i.naturalWidth > 0)"
                           " && document.querySelectorAll('#grid img').length > 0", timeout=30000)


def chromaticity(rgb: np.ndarray) -> np.ndarray:
    rgb = rgb.astype(np.float64)
    return rgb / np.maximum(rgb.sum(axis=-1, keepdims=True), 1.0)


def texture_colour(folder: Path) -> np.ndarray:
    """The median chromaticity of the object's front albedo (the middle third of the unwrapped 360 deg map)."""
    with Image.open(folder / "albedo.png") as im:
        albedo = np.asarray(im.convert("RGB"))
    w = albedo.shape[1]
    return np.median(chromaticity(albedo[:, w // 3 : 2 * w // 3]).reshape(-1, 3), axis=0)


def assert_draws_object(shot: np.ndarray, folder: Path) -> None:
    """The viewer's middle shows the object's colour (tone mapping desaturates it a little), not the grey
    backdrop, and its rim shows the backdrop (the object sits inside the view)."""
    h, w, _ = shot.shape
    centre = shot[int(0.35 * h) : int(0.65 * h), int(0.4 * w) : int(0.6 * w)]
    rim = np.concatenate([shot[: h // 20].reshape(-1, 3), shot[-h // 20 :].reshape(-1, 3),
                          shot[:, : w // 20].reshape(-1, 3), shot[:, -w // 20 :].reshape(-1, 3)])
    seen = np.median(chromaticity(centre).reshape(-1, 3), axis=0)
    expected = texture_colour(folder)
    assert np.abs(seen - expected).max() < 0.08, (seen, expected)
    assert np.abs(seen - chromaticity(VIEWER_BACKDROP)).max() > 0.1, seen
    assert (np.abs(centre.astype(int) - VIEWER_BACKDROP).max(axis=-1) < 12).mean() < 0.05
    assert (np.abs(rim.astype(int) - VIEWER_BACKDROP).max(axis=-1) < 12).mean() > 0.9


def wait_for_model(page) -> None:
    page.wait_for_function("document.querySelector('model-viewer') && document.querySelector('model-viewer').loaded",
                           timeout=60000)
    page.wait_for_timeout(1500)  # the first frames after loading fade the model in


def test_overview_and_3d_view_served(browser, served: str, results: Path) -> None:
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    watch = PageWatch(page)
    page.goto(served + "/index.html")
    wait_for_thumbnails(page)
    keep(page.screenshot(), "gallery-overview.png")
    ids = page.eval_on_selector_all(".card", "cards => cards.map(c => c.dataset.id)")
    status = {d.name: json.loads((d / "material.json").read_text())["quality"]["status"] for d in results.iterdir()
              if (d / "material.json").is_file()}
    reviewed = [i for i in ids if status[i] != "ok"]
    assert len(ids) == 6 and ids[: len(reviewed)] == reviewed and "synthetic_vase_3" in reviewed  # review first
    page.select_option("#sort", "material:pitch:desc")
    pitches = {d.name: json.loads((d / "material.json").read_text())["pitch"] for d in results.iterdir()
               if (d / "material.json").is_file()}
    assert page.eval_on_selector_all(".card", "cards => cards.map(c => c.dataset.id)") == sorted(
        pitches, key=lambda k: -pitches[k])
    page.fill("#search", "vase_2")
    assert page.eval_on_selector_all(".card", "cards => cards.map(c => c.dataset.id)") == ["synthetic_vase_2"]
    page.fill("#search", "storage")  # by the catalogue's title
    assert page.eval_on_selector_all(".card", "cards => cards.map(c => c.dataset.id)") == ["synthetic_vase_3"]
    page.click(".card[data-id='synthetic_vase_3']")
    assert "Rogers Fund, 1917 · CC0" in page.inner_text(".attribution")
    link = page.locator(".attribution a")
    assert link.get_attribute("href") == "https://www.metmuseum.org/art/collection/search/1"
    page.wait_for_function("document.querySelector('model-viewer') && document.querySelector('model-viewer').loaded",
                           timeout=60000)
    page.click("text=← all objects")
    page.fill("#search", "")

    page.click(f".card[data-id='{OBJECT}']")
    wait_for_model(page)
    keep(page.screenshot(), "gallery-object.png")
    viewer = page.locator("model-viewer")
    shot = keep(viewer.screenshot(), "gallery-3d.png")
    assert_draws_object(shot, results / OBJECT)

    page.click("text=sunset")
    page.wait_for_timeout(1500)
    relit = keep(viewer.screenshot(), "gallery-3d-sunset.png")
    assert np.abs(relit.astype(int) - shot.astype(int)).mean() > 2.0  # the lighting changed the picture
    assert not watch.problems, watch.problems
    page.close()


def test_opened_from_disk(browser, results: Path) -> None:
    """From file:// the page cannot fetch mesh.glb: it asks for the files, then draws and relights them."""
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    watch = PageWatch(page)
    page.goto((results / "index.html").as_uri())
    wait_for_thumbnails(page)
    page.click(f".card[data-id='{OBJECT}']")
    page.wait_for_selector(".pictures img")
    assert "radar serve" in page.inner_text(".viewer")  # says how else to get the 3D view
    assert page.locator("model-viewer").count() == 0
    page.set_input_files(".viewer input[type=file]",
                         [results / OBJECT / "mesh.glb", results / OBJECT / "env_viewer.hdr"])
    wait_for_model(page)
    viewer = page.locator("model-viewer")
    shot = keep(viewer.screenshot(), "gallery-3d-from-disk.png")
    assert_draws_object(shot, results / OBJECT)
    assert page.eval_on_selector_all(".envs button", "bs => bs.map(b => b.textContent)") == [
        "recovered", "overcast", "studio", "sunset", "two_lights"]
    page.click("text=studio")
    page.wait_for_timeout(1500)
    studio = keep(viewer.screenshot(), "gallery-3d-from-disk-studio.png")
    assert np.abs(studio.astype(int) - shot.astype(int)).mean() > 2.0
    assert not watch.problems, watch.problems
    page.close()


@pytest.fixture(scope="module")
def multiview(tmp_path_factory) -> Path:
    """`pot` (three photos and an unreadable one) and `single` de-rendered by the fake model, with the report."""
    out = derender_pot(tmp_path_factory.mktemp("multiview"))
    write_report(out, [])
    return out


def test_an_object_with_several_views_is_one_card_with_its_views(browser, multiview: Path) -> None:
    server = make_server(multiview, 0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    watch = PageWatch(page)
    page.goto(f"http://127.0.0.1:{server.server_address[1]}/index.html")
    wait_for_thumbnails(page)
    keep(page.screenshot(), "gallery-multiview-overview.png")
    assert sorted(page.eval_on_selector_all(".card", "cards => cards.map(c => c.dataset.id)")) == ["pot", "single"]
    assert page.locator(".card[data-id='single'] .views").count() == 0  # one photo: a plain card, no strip
    captions = page.eval_on_selector_all(".card[data-id='pot'] .views figcaption", "fs => fs.map(f => f.textContent)")
    assert captions[0] == "front0°" and "brokenleft out" in captions and len(captions) == 4  # name, turn
    assert page.locator(".card[data-id='pot'] .views img").count() == 3  # the unreadable photo has no picture
    page.click(".card[data-id='pot']")
    page.wait_for_function("[...document.querySelectorAll('#detail .views img')].every(i => i.complete && "
                           "i.naturalWidth > 0) && document.querySelectorAll('#detail .views img').length === 3")
    listed = page.inner_text("#detail .views")
    assert "broken" in listed and "left out: unreadable" in listed and "0° · used" in listed
    assert "3D view" in page.inner_text(".pictures") or "fused" in page.inner_text(".pictures")
    wait_for_model(page)
    keep(page.screenshot(full_page=True), "gallery-multiview-object.png")
    assert page.eval_on_selector("model-viewer", "mv => mv.src").endswith("pot/mesh.glb")  # the fused texture's
    assert not watch.problems, watch.problems
    page.close()
    server.shutdown()
    server.server_close()


def synthetic_collection(results: Path, root: Path, n: int, views_from: Path | None = None) -> None:
    """`n` object folders holding what the overview reads, from one de-rendered object (material.json with a
    made-up quality record, the thumbnail, the viewer's lighting; with `views_from`, a multi-view object's views
    and their pictures)."""
    source = results / OBJECT
    material = json.loads((source / "material.json").read_text())
    if views_from is not None:
        material["views"] = json.loads((views_from / "material.json").read_text())["views"]
    rng = np.random.default_rng(0)
    for k in range(n):
        folder = root / f"obj_{k:04d}"
        folder.mkdir()
        for name in (THUMBNAIL_FILE, "env_viewer.hdr", "relit_studio.png"):
            shutil.copyfile(source / name, folder / name)
        if views_from is not None:
            shutil.copytree(views_from / "views", folder / "views")
        status = ("ok", "review", "failed")[k % 7 % 3]
        material["quality"] = {"status": status, "reasons": [] if status == "ok" else ["made up"],
                               "silhouette_iou": float(rng.uniform(0.5, 1)), "symmetry": float(rng.uniform(0.5, 1)),
                               "recon_psnr": float(rng.uniform(15, 30)), "appendage_fraction": 0.0,
                               "cut_edges": [], "frame_coverage": 0.5}
        (folder / "material.json").write_text(json.dumps(material))
        os.utime(folder / THUMBNAIL_FILE)  # newer than material.json: the report keeps the copied thumbnail
        os.utime(folder / "env_viewer.hdr")


@pytest.mark.parametrize("several_views", [False, True], ids=["one-view", "multi-view"])
def test_a_thousand_objects_paint_in_under_3_s(browser, results: Path, multiview: Path, tmp_path: Path,
                                               several_views: bool) -> None:
    root = tmp_path / "thousand"
    root.mkdir()
    synthetic_collection(results, root, 1000, multiview / "pot" if several_views else None)
    start = time.perf_counter()
    write_report(root, [])
    report_s = time.perf_counter() - start
    server = make_server(root, 0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    watch = PageWatch(page)
    start = time.perf_counter()
    page.goto(f"http://127.0.0.1:{server.server_address[1]}/index.html")
    page.wait_for_function("performance.getEntriesByName('first-contentful-paint').length > 0", timeout=30000)
    paint_ms = page.evaluate("performance.getEntriesByName('first-contentful-paint')[0].startTime")
    cards = page.locator(".card").count()
    for _ in range(20):  # scroll the page of cards to its end: lazy thumbnails load as they come in
        page.mouse.wheel(0, 1000)
        page.wait_for_timeout(50)
    wait_for_thumbnails(page)
    scrolled_s = time.perf_counter() - start
    page.click("text=next ›")
    page.wait_for_selector(".card[data-id]")
    page.close()
    server.shutdown()
    server.server_close()
    views = "4" if several_views else "1"
    print(f"\n1,000 objects ({views} views each): report {report_s:.2f} s, first contentful paint {paint_ms:.0f} ms, "
          f"{cards} cards on the first page, all scrolled and thumbnails loaded after {scrolled_s:.2f} s, data.js "
          f"{(root / '.gallery' / 'data.js').stat().st_size / 1000:.0f} KB")
    assert cards == 120
    assert paint_ms < FIRST_PAINT_LIMIT_MS
    assert not watch.problems, watch.problems
