"""Interim: points on a material's surface for :mod:`.surface_values` (to be replaced by the
fast, cached sampling)."""

from __future__ import annotations

import numpy as np

from . import shade

__all__ = ["surface_samples"]


class _Samples:
    def __init__(self, material):
        self.material = material
        self._uv: dict = {}
        self.weights = None
        self.count = 0
        self.uv("")

    def uv(self, name: str):
        if name in self._uv:
            return self._uv[name]
        uvs, weights = [], []
        for obj in shade._users(self.material):
            found = shade._face_samples(obj, self.material, name)
            if found is None:
                continue
            uv, area = found
            uvs.append(uv.reshape(-1, 2))
            weights.append(np.repeat(area / uv.shape[1], uv.shape[1]))
        if not uvs:
            self._uv[name] = None
            return None
        value = np.concatenate(uvs)
        if self.weights is None:
            self.weights = np.concatenate(weights)
            self.count = len(value)
        self._uv[name] = value
        return value

    def image(self, image, uv, extension):
        pixels, _ = shade._image_pixels(image)
        height, width = pixels.shape[:2]
        if extension == "REPEAT":
            uv = uv - np.floor(uv)
        column = np.clip((uv[:, 0] * width).astype(np.int64), 0, width - 1)
        row = np.clip((uv[:, 1] * height).astype(np.int64), 0, height - 1)
        rgb = pixels[row, column]
        return np.concatenate([rgb, np.ones((len(rgb), 1))], axis=1)


def surface_samples(material, progress=None):
    return _Samples(material)
