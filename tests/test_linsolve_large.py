"""The large-net linear algebra of `solver.linsolve`: MKL PARDISO called directly on the
pattern's index arrays (kept per net, analysed again when the pattern changes), and the
backward-error norm. PARDISO tests skip when `pypardiso` (the `pardiso` extra) is absent."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from printgen.solver.linsolve import Pardiso, pardiso_available, row_sum_norm

needs_pardiso = pytest.mark.skipif(not pardiso_available(), reason="pypardiso not installed")
LINEAR = 1e-10  # relative residual |b - S x| / |b| of a direct solve of a well-conditioned S


def _grid_spd(n: int, shift: float) -> sp.csr_matrix:
    """The upper triangle (CSR) of an n^2 x n^2 grid Laplacian plus shift I: SPD for shift > 0,
    indefinite for shift < 0 (shift inside the spectrum)."""
    lap = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    eye = sp.identity(n)
    full = sp.kron(lap, eye) + sp.kron(eye, lap) + shift * sp.identity(n * n)
    upper = sp.triu(full).tocsr()
    upper.sort_indices()
    return upper


def _full(upper: sp.csr_matrix) -> sp.csr_matrix:
    return (upper + sp.triu(upper, 1).T).tocsr()


def _residual(upper: sp.csr_matrix, x: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(_full(upper) @ x - b) / np.linalg.norm(b))


@needs_pardiso
def test_pardiso_refactorizes_on_the_same_pattern_without_a_new_analysis(monkeypatch):
    """New values on the same pattern: the index arrays are kept, no phase 11 (analysis)
    again, and every solve is that of the latest values."""
    upper = _grid_spd(12, 0.5)
    b = np.random.default_rng(5).normal(size=upper.shape[0])
    p = Pardiso()
    phases: list[int] = []
    call = Pardiso._call

    def recording(self, phase, rhs, nrhs=1):
        phases.append(phase)
        return call(self, phase, rhs, nrhs)

    monkeypatch.setattr(Pardiso, "_call", recording)
    p.factor(upper)
    ia = p.ia
    for scale in (2.0, 5.0):
        new = upper.copy()
        new.data = new.data * scale
        p.factor(new)
        assert p.ia is ia  # the same int32 arrays, not converted again
        x = p.solve(b)
        assert _residual(new, x, b) <= LINEAR
        assert np.allclose(x * scale, p.solve(b * scale))
    assert phases.count(11) == 1 and phases.count(22) == 3


@needs_pardiso
def test_pardiso_analyses_a_new_pattern_afresh():
    """A matrix of another pattern (another net on the same instance) is analysed again and
    solved exactly; an indefinite one turns the Cholesky into Bunch-Kaufman LDL^T."""
    p = Pardiso()
    rng = np.random.default_rng(6)
    for n, shift in ((10, 0.5), (14, 0.5), (14, -1.3)):
        upper = _grid_spd(n, shift)
        b = rng.normal(size=upper.shape[0])
        p.factor(upper)
        assert _residual(upper, p.solve(b), b) <= LINEAR
    assert p.solver.mtype == -2  # the last one is indefinite
    p.free()
    assert p.S is None
    p.free()  # twice: nothing left to release, no error


def test_row_sum_norm_is_the_infinity_norm_with_empty_rows():
    rng = np.random.default_rng(7)
    cases = [sp.random(40, 40, density=0.08, random_state=1, format="csr"),
             sp.csr_matrix(np.array([[1.0, -3.0], [0.0, 0.0]])),  # empty last row
             sp.csr_matrix(np.array([[0.0, 0.0, 0.0], [1.0, -3.0, 0.0], [0.0, 0.0, 0.0]])),
             sp.csr_matrix(rng.normal(size=(5, 5)))]
    for A in cases:
        assert row_sum_norm(A) == pytest.approx(float(np.abs(A.toarray()).sum(axis=1).max()),
                                                rel=1e-15)
    assert row_sum_norm(sp.csr_matrix((3, 3))) == 0.0
