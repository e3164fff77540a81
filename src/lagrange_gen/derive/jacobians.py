"""Derivatives that Newton-based steppers need, all exact (no finite differences), each built
only when a kernel that needs it is emitted (see Jacobians)."""

from __future__ import annotations

from collections.abc import Mapping

from .lagrangian import dot

#: name -> what it is (shapes for n coordinates, m constraints).
JACOBIANS = {
    "drhs_dq": "d rhs/dq (n, n) of rhs = Q - h - g",
    "drhs_dqd": "d rhs/dqd (n, n), from dH/dq: dQ/dqd - (D + Hdot - D^T + dH/dt), D_jl = (dH/dq_l qd)_j",
    "dmom_dq": "d momentum_rate/dq (n, n) of momentum_rate = dT/dq - dV/dq + Q",
    "dmom_dqd": "d momentum_rate/dqd (n, n) = D^T + dQ/dqd + db/dq (Q with the T1 forces)",
    "dHw_dq": "d(H(q) w)/dq (n, n) for an input vector w",
    "dQ_dqd": "dQ/dqd (n, n) of the generalized forces",
    "dJw_dq": "d(J(q) w)/dq (m, n)",
    "dJTlam_dq": "d(J(q)^T lam)/dq (n, n), symmetric",
}


class Jacobians(Mapping):
    """The Jacobians by name (JACOBIANS), built on first access and kept.

    ``native(name)`` gives the backend's matrix (for code generation), ``self[name]`` the sympy
    Matrix. Velocity Jacobians are assembled from the first derivatives dH/dq_i and d2Phi/dq2
    that the derivation already has; only d/dq of rhs and momentum_rate differentiates again.
    """

    def __init__(self, o, parts, q, qd, w, lam, to_sympy):
        self._o, self._p = o, parts
        self._q, self._qd, self._w, self._lam = q, qd, w, lam
        self._to_sympy = to_sympy
        self._native, self._sympy, self._d_cache = {}, {}, {}

    def native(self, name):
        if name not in self._native:
            if name not in JACOBIANS:
                raise KeyError(name)
            self._native[name] = getattr(self, f"_{name}")()
        return self._native[name]

    def __getitem__(self, name):
        if name not in self._sympy:
            self._sympy[name] = self._to_sympy(self.native(name))
        return self._sympy[name]

    def __iter__(self):
        return iter(JACOBIANS)

    def __len__(self):
        return len(JACOBIANS)

    def _contract(self, rows, cols, entry):
        return self._o.matrix(rows, cols, [entry(j, l) for j in range(rows) for l in range(cols)])

    def _D(self, vec):
        """D(vec)_jl = sum_k dH/dq_l[j, k] vec_k = d(H vec)/dq with vec held fixed (n, n);
        D(qd) is kept (both velocity Jacobians use it)."""
        key = id(vec)
        if key not in self._d_cache:
            dH, n, zero = self._p["dH"], len(self._q), self._o.native(0)
            self._d_cache[key] = self._contract(n, n, lambda j, l: dot([dH[l][j, k] for k in range(n)], vec, zero))
        return self._d_cache[key]

    def _dQ_dqd(self):
        if "dQ_dqd" not in self._native:
            self._native["dQ_dqd"] = self._o.jacobian(self._p["Q"], self._qd)
        return self._native["dQ_dqd"]

    def _drhs_dq(self):
        return self._o.jacobian(self._p["rhs"], self._q)

    def _drhs_dqd(self):
        D, Hdot, dQ = self._D(self._qd), self._p["Hdot"], self._dQ_dqd()
        n, Ht = len(self._q), self._p["Ht"]
        if Ht is not None:         # h holds dH/dt qd (a rheonomic T2)
            return self._contract(n, n, lambda j, l: dQ[j, l] - (D[j, l] + Hdot[j, l] - D[l, j] + Ht[j, l]))
        return self._contract(n, n, lambda j, l: dQ[j, l] - (D[j, l] + Hdot[j, l] - D[l, j]))

    def _dmom_dq(self):
        return self._o.jacobian(self._p["momentum_rate"], self._q)

    def _dmom_dqd(self):
        D, dQ, n, db = self._D(self._qd), self._dQ_dqd(), len(self._q), self._p["db"]
        return self._contract(n, n, lambda j, l: D[l, j] + dQ[j, l] + db[j, l])

    def _dHw_dq(self):
        return self._D(self._w)

    def _dJw_dq(self):
        d2, n, zero = self._p["d2Phi"], len(self._q), self._o.native(0)
        return self._contract(len(d2), n, lambda i, l: dot([d2[i][k, l] for k in range(n)], self._w, zero))

    def _dJTlam_dq(self):
        d2, n, zero = self._p["d2Phi"], len(self._q), self._o.native(0)
        return self._contract(n, n, lambda k, l: dot([d2[i][k, l] for i in range(len(d2))], self._lam, zero))
