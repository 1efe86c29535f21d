"""One posed RGB-D observation: what every source yields and every stage consumes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import FrameError
from capnav.core.geometry import Intrinsics, check_pose


@dataclass
class Frame:
    """A posed RGB-D frame.

    ``rgb`` uint8 (H, W, 3); ``depth`` float32 metres (H, W), invalid = 0 or non-finite;
    ``T_wc`` 4x4 camera-to-world (OpenCV camera, z-up world). ``gt_instance`` / ``gt_category``
    are optional simulator truth images (int32, 0 = background) that only the simulator
    detector and evaluation may read.
    """

    index: int
    rgb: NDArray[np.uint8]
    depth: NDArray[np.float32]
    K: Intrinsics
    T_wc: NDArray[np.float64]
    timestamp: float = 0.0
    gt_instance: NDArray[np.int32] | None = None
    gt_category: NDArray[np.int32] | None = None

    @property
    def shape(self) -> tuple[int, int]:
        return (self.K.height, self.K.width)

    def validate(self, max_invalid_fraction: float = 1.0) -> Frame:
        """Check shapes, dtypes and the pose; raise ``FrameError`` naming this frame.

        Non-finite depth is not an error (it is masked out everywhere) unless more than
        ``max_invalid_fraction`` of the pixels are invalid.
        """
        h, w = self.shape
        if self.rgb.shape != (h, w, 3) or self.rgb.dtype != np.uint8:
            raise FrameError(self.index, f"rgb must be uint8 ({h}, {w}, 3), got {self.rgb.dtype} {self.rgb.shape}")
        if self.depth.shape != (h, w):
            raise FrameError(self.index, f"depth shape {self.depth.shape} does not match rgb/intrinsics ({h}, {w})")
        if not np.issubdtype(self.depth.dtype, np.floating):
            raise FrameError(self.index, f"depth must be float metres, got {self.depth.dtype}")
        for name in ("gt_instance", "gt_category"):
            img = getattr(self, name)
            if img is not None and img.shape != (h, w):
                raise FrameError(self.index, f"{name} shape {img.shape} does not match ({h}, {w})")
        self.T_wc = check_pose(self.T_wc, frame=self.index)
        if max_invalid_fraction < 1.0:
            valid = np.isfinite(self.depth) & (self.depth > 0)
            bad = 1.0 - float(valid.mean())
            if bad > max_invalid_fraction:
                raise FrameError(self.index, f"{bad:.0%} of depth pixels are invalid (0 or non-finite)")
        return self

    def valid_depth(self) -> NDArray[np.bool_]:
        return np.isfinite(self.depth) & (self.depth > 0)
