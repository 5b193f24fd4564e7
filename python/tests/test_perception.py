"""Perception noise from Python: evaluate and the gymnasium environment."""

import numpy as np
import pytest

import verti


def _strip(rows):
    return [{k: v for k, v in r.items() if k != "wall_time"} for r in rows]


def test_evaluate_with_perception_is_seeded_and_differs_from_truth():
    clean = verti.evaluate("pid", "verti-4", tasks="1-4", jobs=1)
    none = verti.evaluate("pid", "verti-4", tasks="1-4", jobs=1, perception="none")
    noisy = verti.evaluate("pid", "verti-4", tasks="1-4", jobs=2, perception="high")
    again = verti.evaluate("pid", "verti-4", tasks="1-4", jobs=1, perception="high")
    assert _strip(none) == _strip(clean)
    assert _strip(noisy) != _strip(clean)
    assert _strip(noisy) == _strip(again)
    with pytest.raises(ValueError, match="unknown perception"):
        verti.evaluate("pid", "verti-4", tasks="1", perception="foggy")


def test_env_observes_through_the_noise_model():
    kw = dict(task=1, elevation=(8, 1.0))
    clean = verti.NavigateEnv("verti-4", **kw)
    noisy = verti.NavigateEnv("verti-4", perception="high", **kw)
    o1, _ = clean.reset(seed=0)
    o2, _ = noisy.reset(seed=0)
    # the same true start, seen differently
    assert not np.array_equal(o1["state"], o2["state"])
    # the physics is untouched: the same actions move the true vehicle identically
    for _ in range(5):
        clean.step(np.array([0.5, 0.0], dtype=np.float32))
        noisy.step(np.array([0.5, 0.0], dtype=np.float32))
    assert clean.sim().state.pose == noisy.sim().state.pose


def test_env_perception_file_errors_name_the_field(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("pose: {position_drift: -1}\n")
    with pytest.raises(ValueError, match="pose.position_drift"):
        verti.NavigateEnv("verti-4", perception=str(path))
