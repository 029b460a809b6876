"""What `radar derender` reads: collect image files, folders and prepared datasets, and turn each photograph
into the network's square input crop and the same crop at the output resolution (locating the object in photos
that are not square crops yet)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, Union

import numpy as np

from radar_cli.dataset import IMAGE_FILE, MASK_FILE, is_dataset, safe_id
from radar_cli.errors import InputError
from radar_cli.fileio import read_image
from radar_cli.harvest.catalog import CATALOG_NAME, OBJECTS_DIR
from radar_cli.masks.crop import CropBox, cut, mask_box, square_box

IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".webp", ".tif", ".tiff")
FIRST_VIEW_NAMES = ("front", "primary", "a")
"""A multi-view object's photo with one of these stems is its first view (the others' turns are relative to it and
its results are drawn from it); else the first by name."""
CropMode = Literal["auto", "none"]
Backdrop = Literal["keep", "white"]
Resolution = Union[int, Literal["photo"]]
"""The output side in pixels, or `photo`: the crop's own size in the photo (never more than its pixels)."""
DEFAULT_RESOLUTION = 512
MIN_RESOLUTION = 16
# `photo` is capped here: memory and time grow with the side (docs/resolution.md)
MAX_RESOLUTION = 1024


def output_side(resolution: Resolution, native: int) -> int:
    """The side N of the outputs for a crop window `native` photo pixels wide: the requested side, never more
    than the window's pixels (no upsampling) nor MAX_RESOLUTION; `photo` = the window's side (capped).

    Raises:
        InputError: a side outside [MIN_RESOLUTION, MAX_RESOLUTION] or not `photo`.
    """
    if resolution == "photo":
        return max(1, min(native, MAX_RESOLUTION))
    if isinstance(resolution, bool) or not isinstance(resolution, int) or not (
            MIN_RESOLUTION <= resolution <= MAX_RESOLUTION):
        raise InputError(f"resolution must be an integer side in [{MIN_RESOLUTION}, {MAX_RESOLUTION}] px or "
                         f"'photo', got {resolution!r}")
    return max(1, min(resolution, native))


@dataclass(frozen=True)
class InputItem:
    """One photograph to de-render.

    Attributes:
        name: the object's folder name under RESULTS (unique within a run, [A-Za-z0-9._-]).
        image_path: the photo.
        mask_path: a known silhouette (--masks or the dataset sample's), used to crop; None if unknown.
        is_crop: the image is already a network crop (a prepared dataset sample): used whole.
        views: an object photographed from several sides (a sub-folder of an input folder holding two or more
            photos): all its photos, the first view first (image_path); () for a single photo.
    """

    name: str
    image_path: Path
    mask_path: Path | None = None
    is_crop: bool = False
    views: tuple[Path, ...] = ()

    @property
    def multiview(self) -> bool:
        return len(self.views) > 1


@dataclass(frozen=True)
class Failure:
    """An input that could not be de-rendered: the file or folder and a one-line problem."""

    source: str
    problem: str

    def line(self) -> str:
        return f"{self.source}: {self.problem}"


@dataclass(frozen=True)
class Prepared:
    """An input ready for the network.

    Attributes:
        image: S x S x 3 uint8 RGB crop (S = the model's image size).
        crop: the square window of the original photo the crop shows (x0, y0, side in its pixels).
        photo_size: (width, height) of the original photo after EXIF orientation.
        backdrop: `white` if the backdrop was replaced by white, else `kept`.
        silhouette: S x S bool object mask of the crop, when known (located, --masks or the dataset's mask.png):
            the symmetric core of a located or --masks silhouette (handles, spouts, knobs left out).
        photo_image: N x N x 3 uint8, the same window of the photo at the output side N (output_side; the
            backdrop treated as `image`'s); `image` itself when N = S (the default).
        photo_silhouette: N x N bool, `silhouette` at N (None where that is None).
        appendages: N x N bool, the located object's pixels left out of the core; None if not split.
        photo_scene: N x N x 3 uint8, the window at N as photographed (the backdrop not replaced; cut-outs on
            white); `photo_image` before `backdrop` replaced it.
        cut_edges: the photo edges the located object runs into (`top`, `bottom`, `left`, `right`).
        frame_coverage: share of the photo the located object covers; None if not located.
        neighbour_cut: whether a neighbouring object merged into the located one was cut away from it.
        base_off_axis: share of the located object's lowest rows off its symmetric core (a neighbour kept
            with it where large); None if not located.
        above_rim: what of the located object stands above its rim over the mouth, left out of the core (a
            lid's head, a stopper, flowers): its area over the core's, its rise over the rim's width, the share of
            it mirrored about the axis; None if not located.
        painted_fill: on a greyscale photo, the share of the located object filled in as paint of the
            backdrop's grey (masks.locate.Located); None if not located.
        greyscale: whether the located photo is greyscale (its outline read from brightness alone).
    """

    image: np.ndarray
    crop: CropBox
    photo_size: tuple[int, int]
    backdrop: str = "kept"
    silhouette: np.ndarray | None = None
    photo_image: np.ndarray | None = None
    photo_silhouette: np.ndarray | None = None
    appendages: np.ndarray | None = None
    cut_edges: tuple[str, ...] = ()
    frame_coverage: float | None = None
    photo_scene: np.ndarray | None = None
    neighbour_cut: bool = False
    base_off_axis: float | None = None
    above_rim: tuple[float, float, float] | None = None
    painted_fill: float | None = None
    greyscale: bool = False

    def __post_init__(self) -> None:
        if self.photo_image is None:  # frozen: the network's crop is the output crop
            object.__setattr__(self, "photo_image", self.image)
            object.__setattr__(self, "photo_silhouette", self.silhouette)
        if self.photo_scene is None:  # kept through dataclasses.replace, so it stays the unreplaced photo
            object.__setattr__(self, "photo_scene", self.photo_image)

    @property
    def side(self) -> int:
        """N, the side of every image-space output."""
        return int(self.photo_image.shape[0])  # type: ignore[union-attr]


def _is_image(path: Path) -> bool:
    return path.suffix.lower() in IMAGE_SUFFIXES and not path.name.startswith(".")


def _folder_items(folder: Path, masks: Path | None) -> list[InputItem]:
    """Items (names not yet unique) of a folder: a prepared dataset (<split>/<id>/image.png), one split of it
    (<id>/image.png), a `radar fetch` folder (its photos, under OBJECTS_DIR), or else every image under it.

    Dataset samples are named by id, so `radar eval` matches them to their ground truth; with several splits
    the split is prefixed (<split>_<id>)."""
    samples = sorted(folder.glob(f"*/*/{IMAGE_FILE}")) if is_dataset(folder) else []
    if samples:
        several = len({p.parent.parent.name for p in samples}) > 1
        return [InputItem(f"{p.parent.parent.name}_{p.parent.name}" if several else p.parent.name, p,
                          _existing(p.parent / MASK_FILE), is_crop=True) for p in samples]
    samples = sorted(folder.glob(f"*/{IMAGE_FILE}"))
    if samples:
        return [InputItem(p.parent.name, p, _existing(p.parent / MASK_FILE), is_crop=True) for p in samples]
    if (folder / CATALOG_NAME).is_file() and (folder / OBJECTS_DIR).is_dir():  # a `radar fetch` folder
        folder = folder / OBJECTS_DIR  # its photos: <id>.jpg one view each, <id>/ every view of one object
    images = sorted(p for p in folder.rglob("*") if p.is_file() and _is_image(p))
    by_folder: dict[Path, list[Path]] = {}
    for p in images:
        by_folder.setdefault(p.parent, []).append(p)
    items = []
    for p in images:
        views = by_folder[p.parent]
        if p.parent == folder or len(views) < 2:
            items.append(InputItem(p.stem, p, _mask_for(p, masks)))
        elif p == views[0]:
            ordered = tuple(sorted(views, key=lambda v: (v.stem.lower() not in FIRST_VIEW_NAMES, v.name)))
            items.append(InputItem(p.parent.name, ordered[0], views=ordered))
    return items


def _existing(path: Path) -> Path | None:
    return path if path.is_file() else None


def _mask_for(image: Path, masks: Path | None) -> Path | None:
    """A silhouette for `image` in the --masks folder: <stem>.png or <stem>/mask.png."""
    if masks is None:
        return None
    return _existing(masks / f"{image.stem}.png") or _existing(masks / image.stem / MASK_FILE)


def collect_inputs(paths: list[str | Path], masks: str | Path | None = None,
                   exclude: str | Path | None = None) -> tuple[list[InputItem], list[Failure]]:
    """Expand the command line's inputs into photos to de-render.

    Files must have an image suffix; folders are searched recursively for images (other files, such as a
    SOURCES.tsv, are ignored); a folder with no image is a failure. Names are the file stems, made safe and
    unique. Below an input folder, a sub-folder directly holding two or more photos is one object seen from
    several sides (InputItem.views), named by the sub-folder.

    Args:
        paths: files and folders, in order.
        masks: optional folder of known silhouettes (<stem>.png or <stem>/mask.png).
        exclude: a folder whose images are never inputs (the results folder, if it lies inside an input folder).

    Returns:
        (items, failures), items in input order without duplicates.
    """
    masks_dir = Path(masks) if masks is not None else None
    if masks_dir is not None and not masks_dir.is_dir():
        raise InputError(f"{masks_dir}: --masks folder does not exist")
    found: list[InputItem] = []
    failures: list[Failure] = []
    for raw in paths:
        path = Path(raw)
        if path.is_dir():
            items = _folder_items(path, masks_dir)
            if not items:
                failures.append(Failure(str(path), f"folder holds no images ({', '.join(IMAGE_SUFFIXES)})"))
            found.extend(items)
        elif path.is_file():
            if _is_image(path):
                found.append(InputItem(path.stem, path, _mask_for(path, masks_dir)))
            else:
                failures.append(Failure(str(path), f"not an image file (expected {', '.join(IMAGE_SUFFIXES)})"))
        else:
            failures.append(Failure(str(path), "no such file or folder"))
    if exclude is not None:
        skip = Path(exclude).resolve()
        found = [item for item in found if not item.image_path.resolve().is_relative_to(skip)]
    return _unique(found, failures), failures


def _unique(found: list[InputItem], failures: list[Failure]) -> list[InputItem]:
    """The items with safe, unique names; the same file given twice is de-rendered once."""
    items, names, seen = [], set(), set()
    for item in found:
        key = item.image_path.resolve()
        if key in seen:
            continue
        seen.add(key)
        try:
            base = safe_id(item.name)
        except InputError as e:
            failures.append(Failure(str(item.image_path), str(e)))
            continue
        name, k = base, 2
        while name.lower() in names:
            name, k = f"{base}-{k}", k + 1
        names.add(name.lower())
        items.append(dataclasses.replace(item, name=name))
    return items


def resize_mask(mask: np.ndarray, side: int) -> np.ndarray:
    """An H x H bool mask at side x side: its coverage resampled (area down, bilinear up) and cut at 0.5."""
    if mask.shape[0] == side:
        return mask
    return resize_image(mask.astype(np.float32), side) > 0.5


def resize_image(image: np.ndarray, side: int) -> np.ndarray:
    """An H x H (x C) image at side x side (area down, bilinear up)."""
    import cv2

    if image.shape[0] == side:
        return image
    interp = cv2.INTER_AREA if image.shape[0] > side else cv2.INTER_LINEAR
    return cv2.resize(image, (side, side), interpolation=interp)


def whole_photo(photo: np.ndarray) -> CropBox:
    """The smallest square window centred on the photo that contains all of it (sides padded)."""
    h, w = photo.shape[:2]
    side = max(h, w)
    return CropBox((w - side) // 2, (h - side) // 2, side)


def white_backdrop(image: np.ndarray, silhouette: np.ndarray) -> np.ndarray:
    """Put the object of an S x S x 3 uint8 crop on white, through its S x S silhouette; the edge is feathered
    outwards only (~1 px), so the object's own pixels are unchanged."""
    import cv2

    sil = silhouette.astype(np.float32)
    alpha = np.maximum(sil, cv2.GaussianBlur(sil, (0, 0), max(0.5, image.shape[0] / 256)))[..., None]
    return (image * alpha + 255.0 * (1.0 - alpha) + 0.5).astype(np.uint8)


def _known_mask(item: InputItem, shape: tuple[int, int]) -> np.ndarray | None:
    """The item's silhouette (H x W bool) from --masks or its dataset sample, checked against the photo."""
    if item.mask_path is None:
        return None
    mask = read_image(item.mask_path, "L") > 127
    if mask.shape != shape or not mask.any():
        raise InputError(f"{item.mask_path}: mask is empty or its size {mask.shape} is not the photo's {shape}")
    return mask


def _split(silhouette: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A known bool silhouette's symmetric core and appendages."""
    from radar_cli.masks.appendages import symmetric_core

    parts = symmetric_core(silhouette)
    return parts.core, parts.appendages


def prepare(item: InputItem, size: int, crop: CropMode = "auto", backdrop: Backdrop = "white",
            resolution: Resolution = DEFAULT_RESOLUTION) -> Prepared:
    """Read a photo and cut the network's input and the output-resolution crop.

    `auto` locates the object in any framing and crops around its symmetric core (masks.locate; from the
    --masks silhouette if given); `none` pads the whole photo to a square. Dataset samples are crops already and
    are used whole, with their mask as it is. A transparent cut-out's alpha channel is its silhouette.

    Args:
        item: the input.
        size: S, the model's image side.
        crop: `auto` or `none`.
        backdrop: `white` puts the object on white through its silhouette (as synthetic training images are);
            `keep` leaves the photo's backdrop. Without a silhouette (`--crop none`, no mask) it is kept.
        resolution: the output side (output_side): the window is also cut at N = min(resolution, its pixels).

    Returns:
        Prepared; InputError names the file on any problem.
    """
    from radar_cli.masks.locate import split_alpha

    photo = read_image(item.image_path, "RGBA")
    h, w = photo.shape[:2]
    mask = _known_mask(item, (h, w))
    if mask is None and not item.is_crop and crop == "auto":
        return located_input(photo, size, str(item.image_path), backdrop, resolution)
    rgb, _ = split_alpha(photo)
    box = whole_photo(rgb) if item.is_crop or crop == "none" else square_box(mask_box(mask))  # type: ignore
    side = output_side(resolution, box.side)
    image = cut(rgb, box, size)
    photo_image = image if side == size else cut(rgb, box, side)
    photo_silhouette = None if mask is None else cut(mask.astype(np.uint8) * 255, box, side) > 127
    appendages = None
    if photo_silhouette is not None and not item.is_crop:
        photo_silhouette, appendages = _split(photo_silhouette)
    silhouette = None if photo_silhouette is None else resize_mask(photo_silhouette, size)
    return _on_backdrop(Prepared(np.ascontiguousarray(image), box, (w, h), silhouette=silhouette,
                                 photo_image=np.ascontiguousarray(photo_image), photo_silhouette=photo_silhouette,
                                 appendages=appendages), backdrop)


def located_input(photo: np.ndarray, size: int, name: str, backdrop: Backdrop = "white",
                  resolution: Resolution = DEFAULT_RESOLUTION) -> Prepared:
    """The network's input and the output-side crop of a photo (H x W x 3 RGB or x 4 RGBA) whose object is
    located (masks.locate), located at the larger of the two sides and resampled to the other."""
    from radar_cli.masks.locate import locate_object

    work = max(size, MAX_RESOLUTION if resolution == "photo" else int(resolution))
    found = locate_object(photo, work, name)
    side = output_side(resolution, found.box.side)
    h, w = photo.shape[:2]
    located = Prepared(resize_image(found.image, size), found.box, (w, h),
                       silhouette=resize_mask(found.silhouette, size),
                       photo_image=resize_image(found.image, side),
                       photo_silhouette=resize_mask(found.silhouette, side),
                       appendages=resize_mask(found.appendages, side), cut_edges=found.cut_edges,
                       frame_coverage=round(found.frame_coverage, 4), neighbour_cut=found.neighbour_removed,
                       base_off_axis=round(found.base_off_axis, 4),
                       above_rim=(round(found.above_rim[0], 4), round(found.above_rim[1], 4),
                                  round(found.above_rim[2], 4)),
                       painted_fill=round(found.painted_fill, 4), greyscale=found.greyscale)
    return _on_backdrop(located, backdrop)


def _on_backdrop(prepared: Prepared, backdrop: Backdrop) -> Prepared:
    """`white`: the object put on white through its silhouette, at both sides (appendages whited out with the
    backdrop)."""
    if backdrop == "white" and prepared.silhouette is not None:
        white = white_backdrop(prepared.image, prepared.silhouette)
        photo = white
        if prepared.photo_image is not prepared.image:
            assert prepared.photo_image is not None and prepared.photo_silhouette is not None  # set with silhouette
            photo = white_backdrop(prepared.photo_image, prepared.photo_silhouette)
        return dataclasses.replace(prepared, image=white, photo_image=photo, backdrop="white")
    return prepared
