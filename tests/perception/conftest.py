"""Shared fixtures for the perception tests (OpenCV on one thread for stable timings)."""

import cv2
import numpy as np
import pytest

cv2.setNumThreads(1)


@pytest.fixture(scope="session")
def astronaut_bgr() -> np.ndarray:
    """scikit-image's astronaut photograph (a frontal face), as BGR."""
    from skimage import data

    return cv2.cvtColor(data.astronaut(), cv2.COLOR_RGB2BGR)
