import pytest

from percept.sensors import EgoPath, LaneEstimate


def truth_path(gt) -> EgoPath:
    """The ego path from the frame's true lane, so that only the neighbours are under test."""
    lt = gt.lane
    return EgoPath(LaneEstimate(lt.offset_m, lt.heading_rad, lt.curvature_1pm, lt.width_m, 1.0), gt.speed_mps)


@pytest.fixture
def path_from_truth():
    """``path_from_truth(gt)``: the ego path of the true lane (``truth_path``)."""
    return truth_path
