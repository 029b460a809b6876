"""The turntable GIF's shared palette: every pixel drawn by its exactly nearest entry."""

from __future__ import annotations

import io

import numpy as np
from PIL import Image

from radar_cli.derender.export.palette import nearest_entries, quantize
from radar_cli.derender.export.renders import gif_frames


def _brute_nearest(colours: np.ndarray, palette: np.ndarray) -> np.ndarray:
    d = ((colours[:, None, :].astype(np.int64) - palette[None].astype(np.int64)) ** 2).sum(2)
    return d.argmin(1)  # ties to the lower index


def test_nearest_entries_match_a_full_search() -> None:
    rng = np.random.default_rng(3)
    palette = rng.integers(0, 256, (200, 3)).astype(np.int32)
    palette[7] = palette[3]  # a tie: the lower index wins
    colours = np.concatenate([rng.integers(0, 256, (20000, 3)), palette[:20] + 1]).clip(0, 255).astype(np.int32)
    got = nearest_entries(colours, palette)
    assert np.array_equal(got, _brute_nearest(colours, palette))
    assert got[len(colours) - 20 + 3] != 7


def test_clustered_palette_is_still_exact() -> None:
    """Entries packed in one corner of RGB space leave many candidates per cube."""
    rng = np.random.default_rng(4)
    palette = rng.integers(0, 40, (256, 3)).astype(np.int32)
    colours = rng.integers(0, 256, (30000, 3)).astype(np.int32)
    assert np.array_equal(nearest_entries(colours, palette), _brute_nearest(colours, palette))


def test_quantized_frames_draw_the_views_and_load_back() -> None:
    rng = np.random.default_rng(5)
    yy, xx = np.mgrid[0:512, 0:512]
    base = np.stack([xx / 2, yy / 2, (xx + yy) / 4], -1)  # smooth colour ramps
    views = [np.clip(base + rng.normal(0, 2, base.shape) + 20 * k, 0, 255).astype(np.uint8) for k in range(3)]
    indices, palette = quantize(views)
    assert palette.shape[1] == 3 and len(palette) <= 256
    strip = np.concatenate(views, axis=1)
    pillow = Image.fromarray(strip).quantize(256, method=Image.Quantize.MEDIANCUT).convert("RGB")
    pillow_error = np.abs(np.asarray(pillow, np.float64) - strip).mean()  # median cut of every pixel
    error = np.mean([np.abs(palette[i].astype(np.float64) - v).mean() for i, v in zip(indices, views)])
    assert error < 1.05 * pillow_error, (error, pillow_error)
    for index, view in zip(indices, views):
        # no other entry is nearer to any pixel
        pixels = view.reshape(-1, 3)[::97].astype(np.int64)
        got, best = palette[index.reshape(-1)[::97]].astype(np.int64), palette[_brute_nearest(pixels, palette)]
        assert np.array_equal(((got - pixels) ** 2).sum(1), ((best.astype(np.int64) - pixels) ** 2).sum(1))
    buffer = io.BytesIO()
    frames = gif_frames(views)
    frames[0].save(buffer, format="GIF", save_all=True, append_images=frames[1:])
    gif = Image.open(io.BytesIO(buffer.getvalue()))
    for k, index in enumerate(indices):
        gif.seek(k)
        assert np.array_equal(np.asarray(gif.convert("RGB")), palette[index])
