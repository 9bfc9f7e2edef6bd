import numpy as np
import pytest

from gnngarment.body.sampling import farthest_point_sampling


def test_line_picks_extremes_first():
    pos = np.stack([np.linspace(0, 1, 11), np.zeros(11), np.zeros(11)], 1)
    index = farthest_point_sampling(pos, 3, start=5)
    assert index[0] == 5 and set(index[1:]) == {0, 10}


def test_deterministic_distinct_and_spread():
    rng = np.random.default_rng(0)
    pos = rng.standard_normal((500, 3))
    a = farthest_point_sampling(pos, 64)
    assert np.array_equal(a, farthest_point_sampling(pos, 64))
    assert len(set(a.tolist())) == 64
    # The k-th pick is at least as far from the previous picks as any later pick.
    chosen = pos[a]
    gaps = [np.min(np.linalg.norm(chosen[:k] - chosen[k], axis=1)) for k in range(1, 64)]
    assert np.all(np.diff(gaps) <= 1e-12)


@pytest.mark.parametrize(("shape", "count"), [((10, 2), 3), ((10, 3), 0), ((10, 3), 11)])
def test_validation(shape, count):
    with pytest.raises(ValueError):
        farthest_point_sampling(np.zeros(shape), count)
