"""Training the sim people model: the SVM's sign convention, crops, and `percept train-detector` end to end."""

import json

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from percept.cli import app
from percept.detection import DESCRIPTOR_LEN, LinearModel
from percept.detection.training import SEARCH_WINDOW_PX, features, hard_negatives, train_linear_svm, window_crop

runner = CliRunner()


def test_a_linear_svm_scores_its_positives_positive():
    rng = np.random.default_rng(0)
    direction = rng.normal(size=DESCRIPTOR_LEN).astype(np.float32)
    pos = rng.normal(size=(60, DESCRIPTOR_LEN)).astype(np.float32) * 0.1 + direction * 0.05
    neg = rng.normal(size=(120, DESCRIPTOR_LEN)).astype(np.float32) * 0.1 - direction * 0.05
    model = train_linear_svm(pos, neg, c=1.0)
    assert np.mean(pos @ model.weights + model.bias > 0) > 0.95
    assert np.mean(neg @ model.weights + model.bias < 0) > 0.95
    hard = hard_negatives(model, np.vstack([neg, pos[:5]]), limit=3)  # pos[:5] posing as background
    assert len(hard) == 3 and np.all(hard @ model.weights + model.bias >= 0)
    with pytest.raises(ValueError, match="positives and negatives"):
        train_linear_svm(pos, neg[:0])


def test_crops_are_the_search_window_and_mirroring_is_a_flip():
    img = np.random.default_rng(1).integers(0, 255, (200, 300, 3), np.uint8)
    crop = window_crop(img, (10.0, 20.0, 74.0, 148.0))
    assert crop.shape == (SEARCH_WINDOW_PX[1], SEARCH_WINDOW_PX[0], 3)
    assert window_crop(img, (-5.0, 20.0, 59.0, 148.0)) is None and window_crop(img, (250, 100, 314, 228)) is None
    f, m = features([crop]), features([crop], mirror=True)
    assert f.shape == (1, DESCRIPTOR_LEN) and np.allclose(m, features([cv2.flip(crop, 1)]))
    assert not np.allclose(f, m)


@pytest.mark.slow
def test_train_detector_writes_a_model_that_detect_loads(tmp_path):
    out = tmp_path / "m.npz"
    r = runner.invoke(app, ["train-detector", "--seeds", "1000", "--duration", "10", "--every", "5",
                            "--negatives-from", "highway", "--negative-seeds", "1001", "--first-stage", "inria",
                            "--second-threshold", "-0.25", "--out", str(out)])
    assert r.exit_code == 0, r.output
    rec = json.loads(out.with_suffix(".json").read_text())
    assert rec["positives"] > 20 and rec["random_negatives"] > 100 and rec["hard_negatives"] > 0
    assert 0 <= rec["hard_negatives_traffic"] <= rec["hard_negatives"]
    assert rec["plan"]["seeds"] == [1000] and "crossing seeds 1000" in rec["trained_on"]
    assert rec["plan"]["negative_scenarios"] == ["highway"] and "highway seeds 1001" in rec["trained_on"]
    assert rec["cascade"] == "second stage of inria (its first stage), at a score of -0.25"
    assert rec["first_stage_record"] is None  # OpenCV's model has no training record here
    model = LinearModel.load(out)
    # a cascade: OpenCV's INRIA model finds, the model trained here confirms
    assert np.array_equal(model.weights, LinearModel.inria().weights) and model.second_threshold == -0.25
    assert model.second.weights.shape == (DESCRIPTOR_LEN,) and model.second.second is None
    img = np.full((240, 320, 3), 90, np.uint8)
    cv2.imwrite(str(tmp_path / "grey.png"), img)
    r = runner.invoke(app, ["detect", str(tmp_path / "grey.png"), "--model", str(out), "--json",
                            str(tmp_path / "d.json")])
    assert r.exit_code == 0, r.output
    assert json.loads((tmp_path / "d.json").read_text())["results"][0]["detections"] == []


@pytest.mark.parametrize("args, message", [
    (["--seeds", "105"], "are evaluation seeds"),
    (["--every", "0"], "--every"),
    (["--c", "-1"], "--c"),
    (["--seeds", "x"], "--seeds must look like"),
    (["--condition", "fog"], "unknown condition 'fog'"),
    (["--negative-seeds", "1000,7"], "are evaluation seeds"),
    (["--negative-seeds", "a-b"], "--negative-seeds must look like"),
    (["--negatives-from", "autobahn"], "unknown scenario 'autobahn'"),
    (["--first-stage", "missing.npz"], "model file missing.npz does not exist"),
    (["--second-threshold", "9"], "--second-threshold"),
])
def test_train_detector_bad_input_is_one_line_and_exit_2(args, message, tmp_path, one_line_error):
    one_line_error(runner.invoke(app, ["train-detector", *args, "--out", str(tmp_path / "m.npz")]), message)


def test_the_shipped_sim_model_loads_with_its_training_record():
    from percept.detection.hog import SIM_MODEL_PATH

    m = LinearModel.named("sim")
    assert m.name == "sim" and m.weights.shape == (DESCRIPTOR_LEN,)
    rec = json.loads(SIM_MODEL_PATH.with_suffix(".json").read_text())
    assert rec["positives"] > 1000 and not set(rec["plan"]["seeds"]) & (set(range(20)) | set(range(100, 120)))
    # a cascade: its second stage trained with the traffic scenarios' negatives, its first stage's record kept
    assert m.second is not None and m.second_threshold == -0.5 and rec["hard_negatives_traffic"] > 0
    assert rec["first_stage_record"]["positives"] > 1000 and not rec["first_stage_record"]["plan"].get("negative_scenarios")


def test_a_cascades_record_keeps_its_first_stages_record(tmp_path):
    """A cascade's first stage is its own first stage's record (of a cascade, that record's first stage)."""
    from percept.cli.train_cmd import _first_stage_record

    (tmp_path / "one.json").write_text(json.dumps({"positives": 5}))
    (tmp_path / "two.json").write_text(json.dumps({"positives": 7, "first_stage_record": {"positives": 5}}))
    assert _first_stage_record(str(tmp_path / "one.npz")) == {"positives": 5}
    assert _first_stage_record(str(tmp_path / "two.npz")) == {"positives": 5}
    assert _first_stage_record(str(tmp_path / "none.npz")) is None and _first_stage_record("inria") is None
    assert _first_stage_record("sim")["positives"] > 1000


def test_train_detector_will_not_overwrite_its_first_stage(tmp_path):
    """`--out` on the first stage's own file (the packaged one for `sim`) is refused before any work."""
    from percept.detection.hog import SIM_MODEL_PATH

    assert LinearModel.file_of("sim") == SIM_MODEL_PATH and LinearModel.file_of("inria") is None
    before = SIM_MODEL_PATH.read_bytes()
    r = runner.invoke(app, ["train-detector", "--first-stage", "sim", "--out", str(SIM_MODEL_PATH)])
    assert r.exit_code != 0 and "also an input" in r.output, r.output
    assert SIM_MODEL_PATH.read_bytes() == before
