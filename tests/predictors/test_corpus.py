"""A corpus's recordings and their labels: from file names (subfolder sets, top-level people, robots
apart) or from a manifest, and a one-line error for each way a corpus can be wrong."""

import numpy as np
import pytest

from predictors import PredictorError, write_trace
from predictors.corpus import read_corpus
from predictors.synthetic import head_motion


def recording(path, seed=0):
    path.parent.mkdir(parents=True, exist_ok=True)
    write_trace(path, head_motion(1.0, 30.0, seed))


def labels(recordings):
    return [(r.name, r.device, r.person, r.scene, r.apart) for r in recordings]


def test_file_names_give_device_person_and_scene(tmp_path):
    recording(tmp_path / "walk" / "walk_nyc_user101.csv")
    recording(tmp_path / "walk" / "walk_hill_user101.csv")
    recording(tmp_path / "hmd_orientation_user1.csv")
    recording(tmp_path / "quest_pro_robot_traj2.csv")
    recording(tmp_path / "lab.csv")
    assert labels(read_corpus(tmp_path)) == [
        ("hmd_orientation_user1", "hmd_orientation", "hmd_orientation/user1", None, False),
        ("lab", "lab", "lab", None, False),
        ("quest_pro_robot_traj2", "quest_pro_robot_traj2", "quest_pro_robot_traj2", None, True),
        ("walk_hill_user101", "walk", "walk/user101", "hill", False),
        ("walk_nyc_user101", "walk", "walk/user101", "nyc", False),
    ]


def test_the_recordings_are_read_as_written(tmp_path):
    recording(tmp_path / "a.csv", seed=3)
    (trace,) = [r.trace for r in read_corpus(tmp_path)]
    expected = head_motion(1.0, 30.0, 3)
    assert np.allclose(trace.orientation, expected.orientation) and np.allclose(trace.t, expected.t)


def test_a_manifest_in_the_folder_labels_every_recording(tmp_path):
    recording(tmp_path / "one.csv")
    recording(tmp_path / "set" / "two.csv")
    (tmp_path / "manifest.csv").write_text("file,device,person,scene,apart\none.csv,vive,ann,,\nset/two.csv,vive,bob,office,yes\n")
    assert labels(read_corpus(tmp_path)) == [("one", "vive", "ann", None, False), ("two", "vive", "bob", "office", True)]


def test_a_manifest_given_overrides_the_names(tmp_path):
    recording(tmp_path / "x_user1.csv")
    manifest = tmp_path.parent / f"{tmp_path.name}-labels.csv"
    manifest.write_text("file,device,person,scene,apart\nx_user1.csv,quest,carol,lab,no\n")
    assert labels(read_corpus(tmp_path, manifest)) == [("x_user1", "quest", "carol", "lab", False)]


@pytest.mark.parametrize("manifest, message", [
    ("file,device,person\none.csv,a,b\n", "first line must be file,device,person,scene,apart"),
    ("file,device,person,scene,apart\none.csv,,b,,\n", "line 2: expected file,device,person,scene,apart"),
    ("file,device,person,scene,apart\none.csv,a,b,,maybe\n", "apart yes, no or empty"),
    ("file,device,person,scene,apart\nother.csv,a,b,,\n", "one.csv is in the corpus but not in its manifest"),
])  # fmt: skip
def test_a_bad_manifest_is_one_line_naming_what_is_wrong(tmp_path, manifest, message):
    recording(tmp_path / "one.csv")
    (tmp_path / "manifest.csv").write_text(manifest)
    with pytest.raises(PredictorError, match=message):
        read_corpus(tmp_path)


def test_a_subfolder_recording_must_be_named_for_its_set(tmp_path):
    recording(tmp_path / "walk" / "nyc_user101.csv")
    with pytest.raises(PredictorError, match=r"must be named walk_SCENE_PERSON.csv"):
        read_corpus(tmp_path)


def test_a_folder_without_recordings_is_refused(tmp_path):
    with pytest.raises(PredictorError, match="holds no .csv recordings"):
        read_corpus(tmp_path)
    with pytest.raises(PredictorError, match="is not a folder"):
        read_corpus(tmp_path / "missing")
