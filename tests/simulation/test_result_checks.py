"""A Result file that does not fit together is refused on load and on save, naming the file and
the field (issue 37, item 2): before, an NPZ whose rank had 3 rows where t had 51, whose q had an
extra column, whose t ran backwards (energy drift then 0.0) or whose status was 'weird' loaded
without complaint, and one without ``names`` in its metadata raised a bare KeyError."""

import json
from dataclasses import replace

import numpy as np
import pytest

import projeq as pq


def _result(n: int = 51) -> pq.Result:
    """A hand-made Result of a two-coordinate model with a rank history (no simulation): n rows."""
    t = np.linspace(0.0, 1.0, n)
    return pq.Result(t=t, q=np.column_stack((t, -t)), s_dot=np.ones((n, 2)), kinetic=t**2, potential=-t,
                     constraint_residual=np.zeros((n, 1)), names=("a", "b"), coordinates=(("a.angle", "rad"),
                     ("b.angle", "rad")), velocities=(("a.angle_dot", "rad/s"), ("b.angle_dot", "rad/s")),
                     rank=np.ones(n, dtype=int), mobility=np.ones(n, dtype=int))


def _altered(tmp_path, arrays: dict = (), meta: dict = ()):
    """Path of a good Result's NPZ with ``arrays`` replaced and ``meta`` entries replaced (None:
    removed), as a file written by hand or altered would be."""
    path = tmp_path / "run.npz"
    _result().save(path)
    with np.load(path) as data:
        contents = {name: data[name] for name in data.files}
    fields = json.loads(str(contents["meta"]))
    for key, value in dict(meta).items():
        fields.pop(key) if value is None else fields.__setitem__(key, value)
    np.savez(path, **(contents | dict(arrays) | {"meta": json.dumps(fields)}))
    return path


def test_a_good_result_round_trips(tmp_path):
    """Passes if the hand-made Result saves and loads back equal (the checks refuse no good file)."""
    _result().save(tmp_path / "good")
    loaded = pq.Result.load(tmp_path / "good.npz")
    assert np.array_equal(loaded.q, _result().q) and np.array_equal(loaded.rank, _result().rank)


T = np.linspace(0.0, 1.0, 51)


@pytest.mark.parametrize("arrays, meta, words", [
    ({"rank": np.ones(3, dtype=int)}, {}, r"field 'rank' has shape \(3,\) where t has 51 rows: expected \(51,\)"),
    ({"q": np.zeros((51, 3))}, {}, r"field 'q' has shape \(51, 3\) where t has 51 rows: expected \(51, 2\), one "
                                   r"column per coordinate name"),
    ({"s_dot": np.zeros(51)}, {}, r"field 's_dot' has shape \(51,\) where t has 51 rows: expected \(51, 2\)"),
    ({"kinetic": np.zeros(50)}, {}, r"field 'kinetic' has shape \(50,\) where t has 51 rows"),
    ({"t": T[::-1].copy()}, {}, r"field 't' runs backwards at row 1 \(1 s, then 0.98 s\); output times increase"),
    ({"t": np.where(T == 0.5, np.nan, T)}, {}, r"field 't' must be one finite time per output row"),
    ({}, {"status": "weird"}, r"field 'status' is 'weird', not one of \{0: 'finished'"),
    ({}, {"names": None}, r"field 'names' is missing from the metadata"),
    ({}, {"colour": "red"}, r"field 'colour' is not a field of a Result"),
    ({"q_events_0": np.zeros((2, 2)), "t_events_0": np.zeros(1), "s_dot_events_0": np.zeros((1, 2))}, {},
     r"field 't_events_0' has shape \(1,\), q_events_0 \(2, 2\)"),
], ids=["rank-3-rows", "q-extra-column", "s_dot-1d", "kinetic-short", "t-backwards", "t-nan", "status-weird",
        "no-names", "unknown-field", "event-rows"])
def test_a_file_that_does_not_fit_together_is_refused_naming_file_and_field(tmp_path, arrays, meta, words):
    """Passes if each altered file is a ValueError beginning with the path and naming the field."""
    path = _altered(tmp_path, arrays, meta)
    with pytest.raises(ValueError, match=rf"^path: '{path}': {words}"):
        pq.Result.load(path)


@pytest.mark.parametrize("change, words", [
    ({"t": T[::-1].copy()}, r"field 't' runs backwards"),
    ({"status": 7}, r"field 'status' is 7, not one of"),
    ({"q": np.zeros((51, 3))}, r"field 'q' has shape \(51, 3\)"),
    ({"rank": np.ones(3, dtype=int)}, r"field 'rank' has shape \(3,\)"),
], ids=["t-backwards", "status-7", "q-extra-column", "rank-3-rows"])
def test_save_refuses_what_load_would_and_writes_nothing(tmp_path, change, words):
    """Passes if Result.save of a Result that does not fit together is a ValueError naming the
    file and the field, and no file is left."""
    with pytest.raises(ValueError, match=rf"^Result.save\('{tmp_path / 'run.npz'}'\): {words}"):
        replace(_result(), **change).save(tmp_path / "run.npz")
    assert not list(tmp_path.iterdir())
