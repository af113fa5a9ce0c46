r"""Exact IK of an arm NEAR a closed-form family, seeded by its nominal arm's closed form.

The nominal arm (:mod:`om_redundant.om.nominal`) is the model side: its twists are exactly
0, +-90 or 180 deg, its reversed axes flipped, its fixed rows merged, so the OM solver
(system (9) and the bounded search, ``ckernels.Solver``) finds every root of it. The real
arm differs by :math:`T_{real}(q) = T_{nom}(q)\,D(q)^{-1}` with :math:`D(q) = T_{real}(q)^{-1}
T_{nom}(q)` close to the identity. Each nominal root of the target T in configuration c is a
seed:

1. ``ckernels.polish`` refines it on the exact chain (damped Gauss-Newton with the real FK,
   and the arm angle psi as a seventh row on 7-DOF arms);
2. a seed that does not verify takes the OM fixed point on :math:`T\,D(q)`:
   :math:`q_{k+1} = \mathrm{IK}_{nom}(T\,D(q_k), c)` (the nominal root nearest
   :math:`q_k`), whose fixed point reaches T on the real arm, then polish again.

Every answer is verified like the rest of the solver's: the real arm's FK within the
tolerances, and the configuration by the nominal model's branch quantities
(:meth:`NearKernel.holds`). What the nominal arm's bounded search misses near the edge of
reach, and roots that no seed leads to, are misses: ``benchmarks/near_family.py`` measures
their rate.
"""

from __future__ import annotations

import itertools

import numpy as np

from .. import ckernels
from . import system
from .model import ModelArm
from .nominal import NominalArm

#: Gauss-Newton iterations of one polish.
POLISH_ITERATIONS = 30
#: Steps of the fixed point on T D(q) for a seed that polish does not bring home.
FIXED_POINT_STEPS = 20
#: Joint-space distance (rad) under which two roots are one (csrc's OM_SAME_ROOT).
SAME_ROOT = 1e-9
#: Joint-space distance (rad) under which two verified roots are one root found twice near a
#: fold (where the residual is flat to second order), the more accurate kept (csrc's OM_ONE_ROOT).
ONE_ROOT = 1e-6
#: Fractions by which a target the seeds do not lead to is pulled toward the base (the real
#: arm may reach a little farther than the nominal one).
PULL = (1e-4, 1e-3, 1e-2)
#: Distances (m) by which the target is also shifted along each axis of
#: the root frame, both ways: a fold of the real arm's roots lies in any direction of the
#: pose space (e.g. the shoulder's, where the wrist centre meets the cylinder of the lateral
#: offset about joint 1's axis, and the real arm has a pair of roots the nominal arm lacks).
SHIFT = (1e-3,)
#: Fractions by which the target is pushed away from the base for the same purpose (an inner
#: fold, where two roots in c meet and the nominal arm's pair begins farther out).
PUSH = (1e-3,)
#: |Branch quantity| of a nominal root in a neighbouring configuration within which it also
#: seeds c's roots from the start (the real arm's branch boundary lies elsewhere).
BOUNDARY = 0.05
#: Smallest singular value of the exact chain's Jacobian (with the arm angle's gradient on a
#: 7-DOF arm) below which an exact root is searched for a fold partner.
FOLD = 1e-2
#: Multiples of a fold partner's estimated distance tried as seeds.
PARTNER_STEPS = (1.0, 0.5, 2.0)
#: Step (rad) of the second difference along the fold's null direction.
FOLD_STEP = 1e-4
#: Position error (m) of a stalled polish under which it is taken as beside a fold of the
#: real arm's roots (:meth:`NearKernel._refined`).
STALL = 1e-2


class NearKernel:
    """The compiled solver's interface (``ckernels.Solver``) for an arm near a family.

    Joint vectors in and out are the REAL arm's; the nominal solver works in nominal joint
    coordinates :math:`q_n = f \\odot q` (:attr:`NominalArm.flip`).

    Args:
        nominal: The arm and its nominal arm.
        om: The closed-form model of the nominal arm.
        data: The nominal arm's kernel data (:func:`~om_redundant.om.kernel_data.kernel_data`).
        solution_type, configuration_type: As ``ckernels.Solver`` takes them.
    """

    def __init__(self, nominal: NominalArm, om: ModelArm, data: system.SolverData, **types):
        self._nominal = ckernels.Solver(data, **types)
        self._real = nominal.real
        self._flip = nominal.flip
        exact = nominal.exact
        self._exact = exact
        self._nominal_chain = nominal.arm.chain
        self._table = system.as_kernel_array(exact.table)
        self._T_base_root = system.as_kernel_array(np.linalg.inv(exact.T_root_base))
        self._T_tool_flange = system.as_kernel_array(np.linalg.inv(exact.T_flange_tool))
        seven = self._real.dof == 7
        self._P = system.as_kernel_array(om.params) if seven else None
        self._model_table = system.as_kernel_array(om.model.chain.table) if seven else None
        self._tolerances = (data.position_tolerance, data.orientation_tolerance)
        self._all_signs = list(itertools.product((1, -1), repeat=len(om.sign_names)))

    # -- the Solver interface -------------------------------------------------------------

    def solve_pose(self, T, configuration) -> None:
        """None: every solve of a near arm takes the general path."""
        return None

    def solve(self, T, signs, redundancy, hint, q_out) -> tuple[int, float, float, int, bool]:
        """One solve: the root nearest the hint (without one, the first within the limits)."""
        roots, evals = self._roots(T, signs, redundancy, hint)
        if not roots:
            q_out[:] = np.nan
            return self._failure(T, signs, redundancy), np.nan, np.nan, evals, False
        shifted = [self._representative(q, hint) for q, _, _ in roots]
        if hint is not None:
            best = min(range(len(roots)), key=lambda r: float(np.linalg.norm(shifted[r][0] - hint)))
        else:
            best = next((r for r in range(len(roots)) if shifted[r][1]), 0)
        q_out[:] = shifted[best][0]
        return system.OK, roots[best][1], roots[best][2], evals, shifted[best][1]

    def solve_rows(self, T, signs, redundancy, hints, start, stop, q_out, info) -> None:
        """Rows start:stop of a batch (info: status, errors, evaluations, within limits)."""
        for i in range(start, stop):
            hint = None if hints is None else hints[i]
            status, pos, ori, evals, within = self.solve(T[i], signs[i], redundancy[i], hint, q_out[i])
            info[i] = (status, pos, ori, evals, float(within))

    def solve_all(self, T, signs, redundancy, roots_out, info) -> tuple[int, int]:
        """Every root found (verified), shifted into the limits."""
        roots, evals = self._roots(T, signs, redundancy)
        for r, (q, pos, ori) in enumerate(roots):
            shifted, within = self._representative(q, None)
            roots_out[r] = shifted
            info[r] = (pos, ori, float(within))
        return len(roots), evals

    def solve_all_rows(self, T, signs, redundancy, start, stop, roots_out, info, counts, band) -> None:
        """:meth:`solve_all` of rows start:stop of a batch (counts: count, evaluations);
        band is ignored: the nominal arm's seeds always include its band's roots."""
        for i in range(start, stop):
            counts[i] = self.solve_all(T[i], signs[i], redundancy[i], roots_out[i], info[i])

    def configuration_values(self, q, values, redundancy) -> None:
        """The nominal model's branch quantities and arm angle at q."""
        self._nominal.configuration_values(np.ascontiguousarray(self._flip * q), values, redundancy)

    def holds(self, q, signs, redundancy) -> bool:
        """Whether q is in the configuration (the nominal model's branch quantities, the band)."""
        return self._nominal.holds(np.ascontiguousarray(self._flip * q), signs, redundancy)

    # -- the method -----------------------------------------------------------------------

    def _roots(self, T, signs, redundancy, hint=None) -> tuple[list[tuple[np.ndarray, float, float]], int]:
        """Verified roots (real coordinates, position and orientation errors), evaluations.

        Seeds, stage by stage until one leads to a root: the nominal roots in c, and those of
        the neighbouring configurations (one branch flipped) within :data:`BOUNDARY` of it (c
        may hold two real roots where the nominal arm has one in c and one there); in every
        other configuration (near a branch boundary the real arm's root may be the nominal
        arm's in the neighbouring one); of the target pulled toward the base by ``PULL`` in
        every configuration (the real arm may reach a little farther than the nominal one);
        then, whatever the stages found, in c, of the target pushed away from the base by
        ``PUSH`` or shifted by ``SHIFT`` along each axis (a fold of the roots in c in another
        direction, which may lie beside roots already found). Every exact root, in c or
        (reached from another configuration's seed) not, is searched for a fold partner in c.
        A seed that polish does not bring home takes the fixed point on T D(q). The hint, if
        any, is a seed too: at a fold of the psi-constrained map the nominal arm may lack the
        root next to the hint that the real arm has."""
        T = system.as_kernel_array(T)
        R, p = system.flange_target(T, self._T_base_root, self._T_tool_flange)
        R = np.ascontiguousarray(R).ravel()
        psi = float(redundancy[0]) if self._P is not None else 0.0
        signs = tuple(int(s) for s in signs)
        others = [s for s in self._all_signs if s != signs]
        # (target, the seeds' configuration, only seeds within BOUNDARY of c's branches)
        neighbours = [s for s in others if sum(a != b for a, b in zip(s, signs, strict=True)) == 1]
        stages = [[(T, signs, False)] + [(T, s, True) for s in neighbours], [(T, s, False) for s in others]]
        stages.append([(_pulled(T, f), s, False) for f in PULL for s in self._all_signs])
        folds = [_pulled(T, -f) for f in PUSH]
        folds += [_shifted(T, axis, d) for d in SHIFT for axis in range(3) for d in (d, -d)]
        roots: list[tuple[np.ndarray, float, float]] = []
        anchors: list[np.ndarray] = []  # exact roots of T in other configurations
        evals = 0
        for stage in stages:
            for target, seed_signs, boundary in stage:
                seeds, n = self._nominal_roots(target, seed_signs, redundancy)
                if boundary:
                    seeds = [seed for seed in seeds if self._at_boundary(seed, seed_signs, signs)]
                evals += n + len(seeds) * POLISH_ITERATIONS
                for seed in seeds:
                    found = self._refined(T, R, p, psi, seed, signs, redundancy, anchors)
                    if found is None:
                        start = self._fixed_point(T, seed, signs, redundancy)
                        found = self._refined(T, R, p, psi, start, signs, redundancy, anchors)
                    _add_root(roots, found)
            if roots:
                break
        for target in folds:  # always: a pair in c may lie beside roots already found
            seeds, n = self._nominal_roots(target, signs, redundancy)
            evals += n + len(seeds) * POLISH_ITERATIONS
            for seed in seeds:
                _add_root(roots, self._refined(T, R, p, psi, seed, signs, redundancy, anchors))
        for q in [self._flip * q for q, _, _ in roots] + anchors:  # the other root of a close pair
            for seed in self._fold_partners(T, q, psi):
                evals += POLISH_ITERATIONS
                _add_root(roots, self._refined(T, R, p, psi, seed, signs, redundancy))
        if hint is not None:
            evals += POLISH_ITERATIONS
            _add_root(roots, self._refined(T, R, p, psi, self._flip * hint, signs, redundancy))
        return roots, evals

    def _at_boundary(self, seed: np.ndarray, seed_signs: tuple, signs: tuple) -> bool:
        """Whether each branch quantity in which the seed's configuration differs from c is
        within :data:`BOUNDARY` of zero at the seed (nominal coordinates)."""
        values = np.empty(len(signs))
        self._nominal.configuration_values(seed, values, np.empty(1 if self._P is not None else 0))
        return all(abs(v) < BOUNDARY for v, a, b in zip(values, seed_signs, signs, strict=True) if a != b)

    def _nominal_roots(self, T, signs, redundancy) -> tuple[list[np.ndarray], int]:
        """The nominal arm's roots of T in a configuration (nominal coordinates), evaluations."""
        roots = np.empty((system.MAX_ROOTS, self._real.dof))
        info = np.empty((system.MAX_ROOTS, 3))
        n, evals = self._nominal.solve_all(T, signs, redundancy, roots, info)
        return [roots[r].copy() for r in range(n)], evals

    def _refined(
        self, T, R, p, psi, seed, signs, redundancy, anchors: list | None = None, fold: bool = True
    ) -> tuple[np.ndarray, float, float] | None:
        """The seed (nominal coordinates) polished on the exact chain and verified; None if not
        (an exact root in another configuration is appended to ``anchors``, if given).

        A polish that stalls short of T where the exact chain's Jacobian is nearly singular
        stopped at a fold of the real arm's roots (the residual's valley along the fold): the
        roots of the fold's quadratic (:meth:`_fold_partners`) seed the pair on both sides of
        it, one in each neighbouring configuration."""
        if seed is None:
            return None
        q = np.ascontiguousarray(seed, dtype=np.float64).copy()
        ckernels.polish(self._table, R, p, q, POLISH_ITERATIONS, self._P, self._model_table, psi)
        q_real = self._flip * q
        pos, ori = _errors(self._real.fk(q_real), T)
        exact = pos <= self._tolerances[0] and ori <= self._tolerances[1]
        if exact and self.holds(q_real, signs, redundancy):
            return q_real, pos, ori
        if exact and anchors is not None:
            anchors.append(q)
        if exact or not fold or pos > STALL:
            return None
        for start in self._fold_partners(T, q, psi):
            found = self._refined(T, R, p, psi, start, signs, redundancy, anchors, fold=False)
            if found is not None:
                return found
        return None

    def _fold_partners(self, T, q, psi) -> list[np.ndarray]:
        r"""Seeds for the roots of T at a fold next to q (nominal coordinates): q an exact root
        (its partner), or where a polish stalled beside the fold (both roots).

        Where the exact chain's Jacobian J (with the arm angle's gradient on a 7-DOF arm) is
        nearly singular, :math:`J v = \sigma u` with :math:`\sigma` < :data:`FOLD`, two roots of
        (T, psi) meet along v: :math:`u \cdot e(q + t v) \approx r + \sigma t + c t^2 / 2`, e
        the pose (and psi) error, :math:`r = u \cdot e(q)` (zero at a root), c from a second
        difference; the roots t of the quadratic (at an exact root, 0 and its partner
        :math:`-2 \sigma / c`) are tried at multiples :data:`PARTNER_STEPS`; where it has none
        (a real minimum of the residual, or a curvature the second difference misjudges), its
        vertex :math:`-\sigma / c`. The nominal arm may have neither root of the pair, or
        only one (its fold lies elsewhere): these are the roots no nominal seed leads to."""
        J = self._exact.jacobian(q)
        if self._P is not None:
            grad = np.empty(self._real.dof)
            ckernels.arm_angle_gradient(self._P, self._model_table, np.ascontiguousarray(q), grad)
            J = np.vstack([J, grad])
        U, S, Vt = np.linalg.svd(J)
        sigma, u, v = S[-1], U[:, -1], Vt[-1]
        if sigma >= FOLD:
            return []
        h = FOLD_STEP
        e = self._error(T, q, psi)
        r = float(u @ e)
        c = u @ (self._error(T, q + h * v, psi) - 2.0 * e + self._error(T, q - h * v, psi)) / h**2
        if c == 0.0 or not np.isfinite(c):
            return []
        disc = sigma**2 - 2.0 * c * r
        ts = [-sigma / c] if disc < 0.0 else [(-sigma + s * np.sqrt(disc)) / c for s in (1.0, -1.0)]
        return [q + k * t * v for t in ts if abs(t) > SAME_ROOT for k in PARTNER_STEPS]

    def _error(self, T, q, psi) -> np.ndarray:
        """The exact chain's pose error at q (nominal coordinates) against T: position, the
        rotation vector of :math:`R(q) R_T^T` (small angles), and on a 7-DOF arm psi's."""
        F = self._exact.fk(q)
        E = F[:3, :3] @ T[:3, :3].T
        error = [
            F[:3, 3] - T[:3, 3],
            0.5 * np.array([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]]),
        ]
        if self._P is not None:
            grad = np.empty(self._real.dof)
            psi_q = ckernels.arm_angle_gradient(self._P, self._model_table, np.ascontiguousarray(q), grad)
            error.append([_wrap(psi_q - psi)])
        return np.concatenate(error)

    def _fixed_point(self, T, seed, signs, redundancy) -> np.ndarray | None:
        """The OM fixed point q = IK_nom(T D(q), c) from a seed (nominal coordinates)."""
        q = seed
        out = np.empty(self._real.dof)
        for _ in range(FIXED_POINT_STEPS):
            D = np.linalg.solve(self._exact.fk(q), self._nominal_chain.fk(q))
            status, *_ = self._nominal.solve(system.as_kernel_array(T @ D), signs, redundancy, q, out)
            if status != system.OK:
                return None
            step = _distance(out, q)
            q = out.copy()
            if step < SAME_ROOT:
                break
        return q

    def _failure(self, T, signs, redundancy) -> int:
        """The status when no root is found: the nominal arm's, or no solution in c."""
        status, *_ = self._nominal.solve(T, signs, redundancy, None, np.empty(self._real.dof))
        return system.NO_SOLUTION_IN_CONFIGURATION if status == system.OK else status

    def _representative(self, q: np.ndarray, hint: np.ndarray | None) -> tuple[np.ndarray, bool]:
        """Revolute joints shifted by multiples of 2 pi into the limits, nearest to the hint
        (to zero without one), as the compiled solver does; and whether q is within limits."""
        arm = self._real
        target = np.zeros(arm.dof) if hint is None else hint
        q = q.copy()
        inside = True
        for j in range(arm.dof):
            lo, hi = arm.lower[j], arm.upper[j]
            if not arm.revolute[j]:
                inside = inside and lo <= q[j] <= hi
                continue
            best = _wrap(q[j] - target[j]) + target[j]
            if not lo <= best <= hi:
                candidates = [c for c in _wrap(q[j]) + 2 * np.pi * np.arange(-3, 4) if lo <= c <= hi]
                if candidates:
                    best = min(candidates, key=lambda c: abs(c - target[j]))
                else:
                    inside = False
            q[j] = best
        return q, inside


def _add_root(roots: list, found: tuple[np.ndarray, float, float] | None) -> None:
    """Append a verified root unless it is None or one already found: within ONE_ROOT of a
    kept root it is that root, found twice, and the copy with the smaller pose error stays."""
    if found is None:
        return
    for r, (q, pos, ori) in enumerate(roots):
        if _distance(found[0], q) < ONE_ROOT:
            if found[1] + found[2] < pos + ori:
                roots[r] = found
            return
    roots.append(found)


def _wrap(angle):
    return np.remainder(angle + np.pi, 2 * np.pi) - np.pi


def _distance(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(_wrap(a - b)).max())


def _pulled(T: np.ndarray, fraction: float) -> np.ndarray:
    """T with its position pulled toward the root frame's origin by a fraction of it (pushed
    away from it for a negative fraction)."""
    pulled = T.copy()
    pulled[:3, 3] *= 1.0 - fraction
    return pulled


def _shifted(T: np.ndarray, axis: int, distance: float) -> np.ndarray:
    """T with its position moved by ``distance`` (m) along an axis of the root frame."""
    moved = T.copy()
    moved[axis, 3] += distance
    return moved


def _errors(reached: np.ndarray, T: np.ndarray) -> tuple[float, float]:
    """Position (m) and orientation (rad) error of a reached pose against T."""
    E = T[:3, :3].T @ reached[:3, :3]
    s = 0.5 * np.linalg.norm([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]])
    return float(np.linalg.norm(reached[:3, 3] - T[:3, 3])), float(np.arctan2(s, 0.5 * (np.trace(E) - 1.0)))
