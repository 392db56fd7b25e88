"""The layout: a rear camera view (beside the left camera's) only when the recording has a rear rig; a task with
more plots than fit in a row gets rows of its own of equal length."""

import rerun.blueprint as rrb

from percept.review import blueprint, parts
from percept.review.blueprint import ROW_VIEWS, pack_rows
from percept.review.context import CAMERA, REAR_CAMERA


def views(container) -> list:
    """Every view of a blueprint's container, depth first."""
    out = []
    for item in container.contents:
        out += views(item) if isinstance(item, rrb.Container) else [item]
    return out


def test_the_layout_has_a_rear_camera_view_only_with_a_rear_rig():
    part_list = [("control", parts.control)]
    with_rear = {v.name: v for v in views(blueprint(part_list, rear=True).root_container)}
    without = {v.name: v for v in views(blueprint(part_list).root_container)}
    assert "rear camera" in with_rear and "rear camera" not in without
    assert str(with_rear["rear camera"].origin) == REAR_CAMERA and str(with_rear["left camera"].origin) == CAMERA
    assert "3D (follows the ego)" in with_rear and "3D (follows the ego)" in without


def test_a_long_group_of_plots_gets_rows_of_equal_length_and_short_ones_share_a_row():
    def plots(n: int) -> list:
        return [rrb.TimeSeriesView(name=f"p{i}") for i in range(n)]

    rows = pack_rows([plots(2), plots(1), plots(4), plots(ROW_VIEWS)])
    assert [len(r.contents) for r in rows] == [3, 2, 2, 3]
