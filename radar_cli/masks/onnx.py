"""Optional detector: a user-supplied ONNX instance-segmentation model run with onnxruntime (extra `onnx`).

Model contract (export your model to match): one input, float32 N x 3 x H x W RGB in [0, 1] (H, W fixed by
the model, or 512 x 512 if dynamic); outputs `masks` K x 1 x H x W (or K x H x W) probabilities and
optionally `scores` K. Masks scoring below 0.5 or covering < 1% of the image are ignored.
"""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from radar_cli.errors import InputError
from radar_cli.masks.detect import Detection

DEFAULT_SIDE = 512


class OnnxDetector:
    """Callable image (H x W x 3 uint8) -> list[Detection], like `detect`."""

    def __init__(self, model: str | Path | None):
        try:
            import onnxruntime
        except ImportError:
            raise InputError("--detector onnx needs onnxruntime: pip install 'radar-cli[onnx]'") from None
        if model is None or not Path(model).is_file():
            raise InputError(f"{model}: no such ONNX model file")
        try:
            self.session = onnxruntime.InferenceSession(str(model), providers=["CPUExecutionProvider"])
        except Exception as e:  # onnxruntime raises its own exception types for bad files
            raise InputError(f"{model}: not a loadable ONNX model ({str(e).splitlines()[0]})") from None
        inp = self.session.get_inputs()[0]
        self.input_name = inp.name
        dims = inp.shape[2:]
        self.hw = tuple(d if isinstance(d, int) else DEFAULT_SIDE for d in dims)
        self.outputs = [o.name for o in self.session.get_outputs()]

    def __call__(self, image: np.ndarray) -> list[Detection]:
        h, w = self.hw
        x = cv2.resize(image, (w, h), interpolation=cv2.INTER_AREA).astype(np.float32) / 255.0
        result = dict(zip(self.outputs, self.session.run(None, {self.input_name: x.transpose(2, 0, 1)[None]})))
        masks = result.get("masks", next(iter(result.values())))
        masks = masks.reshape(-1, h, w)
        scores = result.get("scores", np.ones(len(masks))).reshape(-1)
        found = []
        sx, sy = image.shape[1] / w, image.shape[0] / h
        for m, score in zip(masks, scores):
            mask = m > 0.5
            if score < 0.5 or mask.mean() < 0.01:
                continue
            ys, xs = np.nonzero(mask)
            box = (xs.min() * sx, ys.min() * sy, (xs.max() + 1) * sx, (ys.max() + 1) * sy)
            # the pipeline warps the mask by one scale factor, so resize it to the photo's aspect first
            scale = 1.0 / sy
            mh, mw = h, max(1, round(image.shape[1] * scale))
            resized = cv2.resize(mask.astype(np.uint8), (mw, mh), interpolation=cv2.INTER_NEAREST) > 0
            found.append(Detection(resized, box, float(score), scale))
        return sorted(found, key=lambda d: -int(d.mask.sum()))
