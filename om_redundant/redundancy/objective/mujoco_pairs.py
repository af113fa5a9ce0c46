"""The pairs ``_core.arm_clearance`` leaves to MuJoCo (kinds it does not compute, cores
touching, boxes touched), by ``mj_geomDistance`` on a scratch ``MjData`` where the pair's two
geoms are placed."""

from __future__ import annotations

import threading

import mujoco
import numpy as np

from ... import _core
from .arm_geoms import BOX, POINT, SEGMENT, ArmCores


class MujocoPairs:
    """A :class:`~om_redundant.Clearance`'s MuJoCo side: its model, a scratch ``MjData`` (taken
    by one call at a time: threads may share the clearance) and its pairs' geom ids.

    Args:
        model: The clearance's model.
        pair_geoms: Each pair's (arm geom id, obstacle geom id, the arm geom's index).
        n_arm: The arm's collision geoms.
        dof: The arm's joints.
    """

    def __init__(self, model: mujoco.MjModel, pair_geoms: list[tuple[int, int, int]], n_arm: int, dof: int):
        self.model, self._pair_geoms, self._n_arm, self._dof = model, pair_geoms, n_arm, dof
        self._n_pairs = len(pair_geoms)
        self.data = mujoco.MjData(model)  # at qpos0: the obstacles placed, and mj_geomDistance's scratch
        mujoco.mj_kinematics(model, self.data)
        self._placed = (self.data.geom_xpos, self.data.geom_xmat)  # (views of the data's arrays)
        # the geom ids of the arm's geoms and of the obstacles, in the cores' order
        self._arm_ids = np.array(list(dict.fromkeys(a for a, _, _ in pair_geoms)))
        self._obstacle_ids = np.array(list(dict.fromkeys(o for _, o, _ in pair_geoms)))
        self._lock = threading.Lock()  # the data is every call's scratch: one call at a time

    def fill(
        self,
        cores: ArmCores,
        q: np.ndarray,
        reach: float,
        near: float,
        dist: np.ndarray,
        fromto: np.ndarray,
        grad: np.ndarray | None,
    ) -> None:
        """The pairs ``_core.arm_clearance`` left (nan: kinds it does not compute, cores
        touching, boxes touched) by ``mj_geomDistance``, the arm geoms placed as it places
        them (all those rows' in one call), and those rows' gradients (in one call)."""
        m, d, n_pairs = self.model, self.data, self._n_pairs
        fromto = fromto.reshape(-1, n_pairs, 6)
        left = np.isnan(dist)
        rows = np.flatnonzero(left.any(axis=1))
        n_arm = self._n_arm
        xpos, xmat = np.empty((len(rows), n_arm, 3)), np.empty((len(rows), n_arm, 9))
        _core.arm_geom_poses(cores, q[rows], xpos, xmat)
        kind, radius, half = cores.kind, cores.radius, cores.half
        cored = (POINT, SEGMENT)
        with self._lock:  # (one fill at a time: the data's poses are its scratch)
            placed_pos, placed_mat = self._placed
            obstacles = self._obstacle_ids
            placed_pos[obstacles], placed_mat[obstacles] = cores.obstacle_pos, cores.obstacle_mat
            for j, (r, pairs) in enumerate(zip(rows.tolist(), _left_pairs(left[rows]), strict=True)):
                placed_pos[self._arm_ids], placed_mat[self._arm_ids] = xpos[j], xmat[j]  # (row r's arm)
                for k in pairs:
                    a, o, i = self._pair_geoms[k]
                    ft = fromto[r, k]
                    found = mujoco.mj_geomDistance(m, d, a, o, reach, ft)
                    b = cores.pairs[k, 1]
                    box_cored = kind[b] == BOX and kind[i] in cored  # (a sphere or capsule's core, a box)
                    if found > 0.0 and (box_cored or (kind[i] == BOX and kind[b] in cored)):
                        # The kernel leaves such a pair where the cores say it overlaps; MuJoCo's
                        # box-capsule distance can be positive for a capsule whose core pierces
                        # a thin box (0.3 % of such pairs, up to 0.09 m): the exact depth instead.
                        arm = _core.GeomPose(xpos[j, i], xmat[j, i], half[i], radius[i])
                        obstacle = _core.GeomPose(placed_pos[o], placed_mat[o], half[b], radius[b])
                        if box_cored:
                            found = _core.box_overlap(arm, obstacle, ft)
                        else:  # (the obstacle's core in the arm's box: its nearest points turned round)
                            found = _core.box_overlap(obstacle, arm, ft)
                            ft[:] = np.roll(ft, 3)
                    dist[r, k] = found
        if grad is not None:
            given = np.empty((len(rows), n_pairs, self._dof))
            given_pairs = _core.PairDistances(dist[rows], fromto[rows], given)
            _core.arm_clearance(cores, q[rows], reach, near, given_pairs, True)
            grad.reshape(-1, n_pairs, self._dof)[rows] = given


def _left_pairs(left: np.ndarray) -> list[list[int]]:
    """Each row's pairs left to MuJoCo (left: (rows, pairs) bools)."""
    return [np.flatnonzero(row).tolist() for row in left]
