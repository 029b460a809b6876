"""The light band a black glaze shows along its flanks is given back to the located vessel; a halo that fades
into the backdrop, a shadow and a card beside the vessel are not. The photos and masks are drawn here."""

from __future__ import annotations

import numpy as np

from radar_cli.masks.refine import iou
from radar_cli.masks.sheen import grow_sheen

N = 256
BACKDROP = 60


def vessel(radius: float = 60.0) -> np.ndarray:
    """N x N bool: an upright body of revolution (an ellipse's outline) between rows 40 and 220, axis at 128."""
    y, x = np.mgrid[0:N, 0:N].astype(np.float64)
    t = (y - 130) / 90
    return (np.abs(x - 128) <= radius * np.sqrt(np.clip(1 - t * t, 0, 1))) & (np.abs(t) <= 1)


def photo(outline: np.ndarray, body: np.ndarray, band: float, seed: int = 0) -> np.ndarray:
    """N x N x 3 uint8: a dark grey backdrop with noise, the vessel's `outline` filled with `band` (its flanks'
    grey) and its `body` black."""
    rng = np.random.default_rng(seed)
    grey = np.full((N, N), float(BACKDROP)) + rng.normal(0, 1.0, (N, N))
    grey[outline] = band
    grey[body] = 20.0
    return np.repeat(np.clip(grey, 0, 255).astype(np.uint8)[..., None], 3, axis=2)


def test_the_glazes_band_is_given_back() -> None:
    whole, body = vessel(60), vessel(53)  # a band 7 px wide at the widest row
    image = photo(whole, body, BACKDROP + 22)
    grown = grow_sheen(body, image)
    assert iou(body, whole) < 0.9 and iou(grown, whole) >= 0.97
    assert not (grown & ~whole).any()


def test_a_halo_that_fades_a_shadow_and_a_card_are_not() -> None:
    whole, body = vessel(60), vessel(53)
    y, x = np.mgrid[0:N, 0:N]
    distance = np.abs(x - 128) - 53 * np.sqrt(np.clip(1 - ((y - 130) / 90) ** 2, 0, 1))
    halo = photo(whole, body, BACKDROP)  # lighter round the outline, fading out over 20 px
    lift = np.where(body, 0, 14 * np.clip(1 - distance / 20, 0, 1) * (np.abs(y - 130) <= 90))
    halo = np.clip(halo + lift[..., None], 0, 255).astype(np.uint8)
    shadow = photo(whole, body, BACKDROP - 25)  # a band darker than the backdrop
    card = photo(whole, body, BACKDROP)
    card[150:220, 160:250] = 200  # a white card standing against the right flank, wider than the reach
    for image in (halo, shadow, card):
        assert (grow_sheen(body, image) == body).all()


def test_nothing_grows_into_the_padding_beyond_the_photo() -> None:
    whole, body = vessel(60), vessel(53)
    image = photo(whole, body, BACKDROP + 22)
    outside = np.zeros((N, N), bool)
    outside[:, 184:] = True  # the photo ends 3 px past the right flank's widest row
    grown = grow_sheen(body & ~outside, image, outside)
    assert not (grown & outside).any()
    assert iou(grown[:, :128], whole[:, :128]) >= 0.97  # the left flank's band is still given back
