"""Scores that compare the pipeline's answers with the simulator's truth."""

from __future__ import annotations

import numpy as np

__all__ = ["iou"]


def iou(a: np.ndarray, b: np.ndarray) -> float:
    """Intersection over union of two boolean masks."""
    union = np.count_nonzero(a | b)
    return np.count_nonzero(a & b) / union if union else 0.0
