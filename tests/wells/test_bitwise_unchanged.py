"""The polynomial wells the pipeline uses give the same bits as before open sides, the cancellation
fix and the root-based search bound (reference: tests/wells/bitwise_reference.npz, commit ee37d31)."""
import numpy as np
import pytest

from tests.wells.bitwise_reference import PATH, compute


@pytest.fixture(scope="module")
def now():
    return compute()


@pytest.mark.parametrize("key", sorted(np.load(PATH).files))
def test_bit_for_bit(now, key):
    ref = np.load(PATH)[key]
    assert now[key].shape == ref.shape and now[key].dtype == ref.dtype
    assert np.array_equal(now[key], ref, equal_nan=True), key
