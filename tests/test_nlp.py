"""Layout: named parts of a column vector (shapes, order, gathered names, reading and writing by name)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from ocpkit.nlp import Layout, Refinement, Stages


def example() -> tuple[Layout, ca.SX, ca.SX, ca.SX]:
    layout = Layout("w")
    a = layout.add("a", 3)
    b = layout.add("B", 2, 3)
    c = layout.add("c")
    return layout, a, b, c


def test_a_column_has_a_flat_index_and_a_matrix_a_column_major_one():
    layout, a, b, c = example()
    np.testing.assert_array_equal(layout.index("a"), [0, 1, 2])
    np.testing.assert_array_equal(layout.index("B"), [[3, 5, 7], [4, 6, 8]])
    np.testing.assert_array_equal(layout.index("c"), [9])
    assert layout.size == 10
    assert (a.shape, b.shape, c.shape) == ((3, 1), (2, 3), (1, 1))


def test_symbol_stacks_the_parts_in_order_like_ca_vec():
    layout, a, b, c = example()
    vector = ca.Function("w", [a, b, c], [layout.symbol()])
    A, B, C = np.array([1.0, 2.0, 3.0]), np.array([[10.0, 11.0, 12.0], [20.0, 21.0, 22.0]]), 7.0
    w = np.asarray(vector(A, B, C)).ravel()
    assert layout.symbol().shape == (10, 1)
    np.testing.assert_array_equal(w, np.concatenate([A, B.ravel(order="F"), [C]]))
    np.testing.assert_array_equal(layout.read(w, "B"), B)
    np.testing.assert_array_equal(layout.read(w, "a"), A)


def test_an_empty_layout_is_an_empty_column():
    layout = Layout("p")
    assert layout.size == 0 and layout.symbol().shape == (0, 1)


def test_a_name_for_gathered_entries_reads_them_in_its_shape():
    layout, *_ = example()
    layout.name("first column and c", np.array([[3, 4], [9, 9]]))
    w = np.arange(10.0) * 10
    np.testing.assert_array_equal(layout.read(w, "first column and c"), [[30.0, 40.0], [90.0, 90.0]])
    assert "first column and c" in layout and "d" not in layout
    assert layout.size == 10  # naming adds no entries


def test_a_name_can_be_given_only_once():
    layout, *_ = example()
    with pytest.raises(ValueError, match="'a'"):
        layout.add("a", 2)
    with pytest.raises(ValueError, match="w already has a part named 'B'"):
        layout.name("B", np.array([0]))


def test_write_broadcasts_a_scalar_and_a_row():
    layout, *_ = example()
    w = np.zeros(layout.size)
    layout.write(w, "B", 5.0)
    np.testing.assert_array_equal(layout.read(w, "B"), np.full((2, 3), 5.0))
    layout.write(w, "B", [1.0, 2.0, 3.0])  # one value per column
    np.testing.assert_array_equal(layout.read(w, "B"), [[1.0, 2.0, 3.0], [1.0, 2.0, 3.0]])
    np.testing.assert_array_equal(w[:3], 0.0)
    assert w[9] == 0.0


def test_write_reshapes_values_of_the_same_size_in_c_order():
    layout, *_ = example()
    w = np.zeros(layout.size)
    layout.write(w, "B", np.arange(6.0))
    np.testing.assert_array_equal(layout.read(w, "B"), [[0.0, 1.0, 2.0], [3.0, 4.0, 5.0]])
    layout.write(w, "a", np.array([[7.0], [8.0], [9.0]]))  # a column for a flat part
    np.testing.assert_array_equal(w[:3], [7.0, 8.0, 9.0])


def test_write_of_the_wrong_size_is_refused():
    layout, *_ = example()
    with pytest.raises(ValueError):
        layout.write(np.zeros(layout.size), "B", [1.0, 2.0])


def test_an_unknown_name_is_a_key_error():
    layout, *_ = example()
    with pytest.raises(KeyError):
        layout.index("nope")


def test_refinement_defaults_change_nothing():
    refinement = Refinement()
    assert refinement.check_fractions.shape == (0,)
    assert refinement.extra_margin == 0.0 and refinement.limit_scale == 1.0
    assert Refinement().check_fractions is not refinement.check_fractions  # no shared mutable default


def test_stages_is_a_frozen_value():
    stages = Stages((2, 2, 2), (1, 1, 0), (0, 1, 0))
    assert stages == Stages((2, 2, 2), (1, 1, 0), (0, 1, 0))
    with pytest.raises(AttributeError):
        stages.nx = (1,)
