"""verti.data: datasets generated in Rust and loaded through the Rust reader."""

import numpy as np
import pytest

import verti


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("data") / "random"
    manifest = verti.data.generate(out, hours=0.02, worlds="verti-2-s1", seed=1,
                                   profile="vertiadaptor", max_trial_seconds=30)
    return out, manifest


def test_load_matches_the_manifest(dataset):
    out, made = dataset
    data, manifest = verti.data.load(out)
    assert manifest == made
    assert manifest["kind"] == "random" and manifest["eval_worlds"] is False
    assert len(data["t"]) == manifest["rows"]
    for name in verti.FEATURES:
        assert name in data, name
    for column in ("trial", "world", "step", "cmd_steering", "cmd_speed", "wheel0_class",
                   "wheel3_friction", "wheel2_soil", "last", "outcome"):
        assert column in data, column
    last = np.asarray(data["last"])
    assert last.sum() == manifest["trials"]
    outcome = np.asarray(data["outcome"], dtype=object)
    # missing outcomes: None in the dict of arrays, NaN once pandas has inferred a string column
    assert not any(isinstance(o, str) for o in outcome[~last])
    assert all(o in ("rollover", "stuck", "timeout", "edge") for o in outcome[last])
    pieces = verti.data.trials(data)
    assert len(pieces) == manifest["trials"]
    assert np.asarray(pieces[0]["t"])[0] == 0.0


def test_errors_name_the_problem(dataset, tmp_path):
    out, manifest = dataset
    with pytest.raises(FileNotFoundError):
        verti.data.load(tmp_path / "missing")
    with pytest.raises(ValueError, match="evaluation"):
        verti.data.generate(tmp_path / "eval", hours=0.01, worlds="verti-1")
    with pytest.raises(ValueError, match="--force"):
        verti.data.generate(out, hours=0.01, worlds="verti-2-s1")
    # a truncated file is reported by name
    broken = tmp_path / "broken"
    broken.mkdir()
    for f in out.iterdir():
        (broken / f.name).write_bytes(f.read_bytes())
    first = manifest["files"][0]
    raw = (broken / first).read_bytes()
    (broken / first).write_bytes(raw[: len(raw) // 2])
    with pytest.raises(ValueError, match=first):
        verti.data.load(broken)
