"""coopctrl.loop.argument_types: the remembered numba types equal ``numba.typeof``'s."""

from collections import namedtuple

import numpy as np
import pytest
from numba import cfunc, typeof, types

from coopctrl.loop.argument_types import argument_type, signature_of

Pair = namedtuple("Pair", "a b")


def _arrays():
    base = np.arange(24.0).reshape(4, 6)
    readonly = base.copy()
    readonly.flags.writeable = False
    return [
        base,                          # C layout
        np.asfortranarray(base),       # F layout
        base[:, ::2],                  # neither (A)
        base[1],                       # a C row
        base[:, 1],                    # a strided column (A)
        readonly,                      # read-only
        np.zeros(()),                  # 0-d
        np.zeros(5, dtype=np.int64),
        np.zeros((2, 3), dtype=np.bool_),
        np.zeros((0, 3)),              # empty
        np.zeros((3, 3, 3))[:, :, 0],  # 2-d view of a 3-d array
    ]


@pytest.mark.parametrize("k", range(11))
def test_arrays_typed_as_numba_types_them(k):
    a = _arrays()[k]
    assert argument_type(a) == typeof(a)
    assert argument_type(a.copy()) == typeof(a.copy())  # a second array of the same kind: the memo, still equal


def test_same_shape_other_layout_or_writability_is_another_type():
    a = np.zeros((3, 4))
    r = a.copy()
    r.flags.writeable = False
    kinds = {argument_type(a), argument_type(np.asfortranarray(a)), argument_type(a[:, ::2]), argument_type(r)}
    assert len(kinds) == 4  # C, F, A and read-only are four numba types: the key tells them apart


def test_tuples_named_tuples_and_scalars():
    arrays = _arrays()
    values = [tuple(arrays), (arrays[0], arrays[0]), Pair(arrays[0], (arrays[1], 2.5)), (True, 1.0),
              True, 0.25, 7, np.float64(1.5), (arrays[0], "text"), -3, 2 ** 63, np.int64(2), np.int32(5), np.bool_(True),
              Pair(np.int64(1), (arrays[1], 4))]
    for v in values:
        assert argument_type(v) == typeof(v), v
    assert signature_of(values) == tuple(typeof(v) for v in values)


def test_a_compiled_stage_is_typed_as_numba_types_it():
    def add(a, b):
        return a + b

    stage = cfunc(types.float64(types.float64, types.float64))(add)
    assert argument_type(stage) == typeof(stage)
    assert argument_type(Pair(stage, np.zeros(2))) == typeof(Pair(stage, np.zeros(2)))
