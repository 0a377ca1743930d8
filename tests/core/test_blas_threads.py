"""One OpenBLAS thread inside the block, the previous counts restored after it."""

import numpy as np

from turntable_pin.core.blas_threads import blas_thread_controls, one_blas_thread


def test_one_thread_inside_and_counts_restored_after():
    np.ones((4, 4)) @ np.ones((4, 4))  # numpy's OpenBLAS is loaded
    controls = blas_thread_controls()
    before = [get() for _, get in controls]
    with one_blas_thread():
        assert all(get() == 1 for _, get in controls)
        product = np.ones((300, 300)) @ np.ones((300, 300))
    assert [get() for _, get in controls] == before
    assert product[0, 0] == 300.0


def test_restored_after_an_error():
    controls = blas_thread_controls()
    before = [get() for _, get in controls]
    try:
        with one_blas_thread():
            raise ValueError("inside")
    except ValueError:
        pass
    assert [get() for _, get in controls] == before
