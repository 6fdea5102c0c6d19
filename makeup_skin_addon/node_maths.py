"""What Blender's colour and math shader nodes compute, in numpy over arrays of samples: the
arithmetic :mod:`.surface_values` evaluates the artist's nodes with (no bpy).

- :func:`blend` -- a Mix node's colour blend modes; :func:`lerp` -- its plain mix.
- :func:`math_node` -- the Math node's (and Vector Math's, per component) operations.
- :func:`rgb_to_hsv`, :func:`hsv_to_rgb` -- the Hue/Saturation/Value node's colour model.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["lerp", "blend", "math_node", "rgb_to_hsv", "hsv_to_rgb"]


def lerp(t: Any, a: Any, b: Any) -> Any:
    """``a`` to ``b`` at ``t``."""
    return a + t * (b - a)


def blend(mode: str, t: Any, a: Any, b: Any) -> Any:
    """Blender's colour blend ``mode`` of ``a`` (below) and ``b`` at factor ``t``, or None."""
    if mode == "MIX":
        return lerp(t, a, b)
    if mode == "ADD":
        return a + t * b
    if mode == "SUBTRACT":
        return a - t * b
    if mode == "MULTIPLY":
        return lerp(t, a, a * b)
    if mode == "SCREEN":
        return 1.0 - (1.0 - t + t * (1.0 - b)) * (1.0 - a)
    if mode == "DIVIDE":
        return np.where(b != 0.0, lerp(t, a, a / np.where(b != 0.0, b, 1.0)), a)
    if mode == "DIFFERENCE":
        return lerp(t, a, np.abs(a - b))
    if mode == "EXCLUSION":
        return np.maximum(lerp(t, a, a + b - 2.0 * a * b), 0.0)
    if mode == "DARKEN":
        return lerp(t, a, np.minimum(a, b))
    if mode == "LIGHTEN":
        return lerp(t, a, np.maximum(a, b))
    if mode == "OVERLAY":
        return np.where(a < 0.5, a * (1.0 - t + 2.0 * t * b),
                        1.0 - (1.0 - t + 2.0 * t * (1.0 - b)) * (1.0 - a))
    if mode == "SOFT_LIGHT":
        screen = 1.0 - (1.0 - b) * (1.0 - a)
        return (1.0 - t) * a + t * ((1.0 - a) * b * a + a * screen)
    if mode == "LINEAR_LIGHT":
        return a + t * (2.0 * b - 1.0)
    return None


def math_node(operation: str, a: Any, b: Any, c: Any) -> Any:
    """Blender's Math (or Vector Math, per component) ``operation``, or None."""
    with np.errstate(divide="ignore", invalid="ignore"):
        table = {
            "ADD": lambda: a + b, "SUBTRACT": lambda: a - b, "MULTIPLY": lambda: a * b,
            "DIVIDE": lambda: np.where(b != 0.0, a / np.where(b != 0.0, b, 1.0), 0.0),
            "MULTIPLY_ADD": lambda: a * b + c,
            "POWER": lambda: np.where(a >= 0.0, np.abs(a) ** b, 0.0),
            "MINIMUM": lambda: np.minimum(a, b), "MAXIMUM": lambda: np.maximum(a, b),
            "ABSOLUTE": lambda: np.abs(a), "SQRT": lambda: np.sqrt(np.maximum(a, 0.0)),
            "FLOOR": lambda: np.floor(a), "CEIL": lambda: np.ceil(a),
            "FRACTION": lambda: a - np.floor(a), "ROUND": lambda: np.floor(a + 0.5),
            "GREATER_THAN": lambda: (a > b).astype(float),
            "LESS_THAN": lambda: (a < b).astype(float),
        }
        function = table.get(operation)
        return None if function is None else function() * np.ones(1)


def rgb_to_hsv(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(h, s, v)`` of colours ``(n, 3)``, h in turns (0..1), as Blender's HSV nodes."""
    high, low = rgb.max(axis=1), rgb.min(axis=1)
    delta = high - low
    safe = np.where(delta > 0.0, delta, 1.0)
    r, g, b = rgb[:, 0], rgb[:, 1], rgb[:, 2]
    h = np.where(high == r, (g - b) / safe, np.where(high == g, 2.0 + (b - r) / safe,
                                                      4.0 + (r - g) / safe))
    h = np.where(delta > 0.0, np.mod(h / 6.0, 1.0), 0.0)
    s = np.where(high > 0.0, delta / np.where(high > 0.0, high, 1.0), 0.0)
    return h, s, high


def hsv_to_rgb(h: np.ndarray, s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Colours ``(n, 3)`` of :func:`rgb_to_hsv`'s ``(h, s, v)``."""
    i = np.floor(h * 6.0)
    f = h * 6.0 - i
    p, q, t = v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f))
    i = i.astype(int) % 6
    choices = [(v, t, p), (q, v, p), (p, v, t), (p, q, v), (t, p, v), (v, p, q)]
    return np.stack([np.choose(i, [c[k] for c in choices]) for k in range(3)], axis=1)
