"""Arms NEAR a closed-form family: shipped arms with their twists moved off 0/90/180 deg.

Run: ``python -m benchmarks.near_family [--n 2000] [--seed 0]``; writes
``results/near_family.md``. For each arm and each deviation eps, every joint row's twist is
moved by +-eps (random signs, seeded), which no closed form takes exactly, so the solver
goes through the nominal arm (``om_redundant.ik.near``). At N random in-limit q: T =
fk(q), c its configuration; a *wrong root* is one of ``solve_all(T, c)`` that misses T
(1e-10 m, 1e-10 rad) or c; a *miss* is a q not among the roots (T is reachable in c).
Also the variants with joint 3's axis reversed and with a fixed row between joints 2 and 3.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import om_redundant as om
from om_redundant.angles import wrap_angles

from .report import write_page

ARMS = ("ur5e", "panda", "iiwa14")
DEVIATIONS = (1e-8, 1e-6, 1e-5, 1e-4, 1e-3)


def bent(arm: om.Arm, deviation: float, rng: np.random.Generator) -> om.Arm:
    """The arm with every joint row's twist moved by +-deviation (rad)."""
    signs = rng.choice((-1.0, 1.0), len(arm.chain.rows))
    rows = [
        om.DHRow(r.a, r.alpha + deviation * s, r.d, r.theta, r.kind) if r.is_joint else r
        for r, s in zip(arm.chain.rows, signs, strict=True)
    ]
    return arm.with_chain(arm.chain.replace_rows(rows), f"{arm.name}-bent-{deviation:g}")


def reversed_joint(arm: om.Arm, joint: int, tilt: float = 0.0) -> om.Arm:
    """The same arm with joint ``joint`` (0-based) turning about its reversed axis: a fixed
    half turn Rx(pi + tilt) before its row, whose theta and d change sign and whose twist
    gains pi; q -> -q (limits mirrored). With tilt = 0 the kinematics are the arm's."""
    rows = list(arm.chain.rows)
    r = arm.chain.joint_rows[joint]
    row = rows[r]
    rows[r] = om.DHRow(row.a, row.alpha + np.pi, -row.d, -row.theta, row.kind)
    rows.insert(r, om.DHRow(alpha=np.pi + tilt, kind=om.JointKind.FIXED))
    lower, upper = arm.lower.copy(), arm.upper.copy()
    lower[joint], upper[joint] = -arm.upper[joint], -arm.lower[joint]
    chain = arm.chain.replace_rows(rows)
    return om.Arm(f"{arm.name}-reversed-{joint + 1}", chain, arm.joint_names, lower, upper)


def fixed_row_between(arm: om.Arm, joint: int, theta: float, d: float, tilt: float) -> om.Arm:
    """The arm with a fixed row Rz(theta) Tz(d) Tx(0) Rx(tilt) inserted after joint ``joint``
    (0-based), compensated in the next joint's row so that the kinematics only differ by the
    tilt."""
    rows = list(arm.chain.rows)
    r = arm.chain.joint_rows[joint + 1]
    nxt = rows[r]
    rows[r] = om.DHRow(nxt.a, nxt.alpha, nxt.d - d, nxt.theta - theta, nxt.kind)
    rows.insert(r, om.DHRow(alpha=tilt, d=d, theta=theta, kind=om.JointKind.FIXED))
    return arm.with_chain(arm.chain.replace_rows(rows), f"{arm.name}-fixed-row-{joint + 1}")


def _random_q(arm: om.Arm, n: int, rng: np.random.Generator) -> np.ndarray:
    lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return rng.uniform(lower, upper, (n, arm.dof))


def measure(arm: om.Arm, n: int, seed: int) -> dict:
    """Wrong roots, misses, worst errors and time of solve_all over n random q."""
    solver = om.OMSolver(arm)
    wrong = misses = roots_total = 0
    worst = [0.0, 0.0]
    start = time.perf_counter()
    for q in _random_q(arm, n, np.random.default_rng(seed)):
        T = arm.fk(q)
        c = solver.configuration_of(q)
        roots = solver.solve_all(T, c)
        roots_total += len(roots)
        misses += not any(
            np.abs(np.where(arm.revolute, wrap_angles(r.q - q), r.q - q)).max() < 1e-7 for r in roots
        )
        for root in roots:
            reached = arm.fk(root.q)
            position = float(np.linalg.norm(reached[:3, 3] - T[:3, 3]))
            E = T[:3, :3].T @ reached[:3, :3]
            s = 0.5 * np.linalg.norm([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]])
            orientation = float(np.arctan2(s, 0.5 * (np.trace(E) - 1.0)))
            worst = [max(worst[0], position), max(worst[1], orientation)]
            wrong += position > 1e-10 or orientation > 1e-10 or not solver.holds(root.q, c)
    seconds = time.perf_counter() - start
    return {
        "arm": arm.name,
        "near": "nominal" if solver.nominal is not None else "exact",
        "q": n,
        "wrong roots": wrong,
        "misses": misses,
        "miss rate": f"{100 * misses / n:.3f} %",
        "roots per (pose, c)": f"{roots_total / n:.3f}",
        "worst error": f"{worst[0]:.1e} m / {worst[1]:.1e} rad",
        "solve_all": f"{1e3 * seconds / n:.2f} ms",
    }


def cases(seed: int) -> list[om.Arm]:
    """The bent arms, then the reversed-axis and fixed-row variants."""
    rng = np.random.default_rng(seed)
    arms = [bent(om.load_arm(name), eps, rng) for name in ARMS for eps in DEVIATIONS]
    ur5e, panda = om.load_arm("ur5e"), om.load_arm("panda")
    arms += [reversed_joint(ur5e, 2, 7e-6), reversed_joint(panda, 3, 7e-6)]
    arms += [fixed_row_between(ur5e, 1, 0.3, 0.02, 1e-4), fixed_row_between(panda, 1, 0.3, 0.0, 1e-4)]
    return arms


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2000, help="random joint vectors per arm")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rows = []
    for arm in cases(args.seed):
        rows.append(measure(arm, args.n, args.seed))
        print(rows[-1], flush=True)
    keys = list(rows[0])
    total_q = sum(r["q"] for r in rows)
    lines = [
        f"# Arms near a closed-form family ({args.n:,} random q per arm, seed {args.seed})",
        "",
        f"Total: {sum(r['wrong roots'] for r in rows)} wrong roots, "
        f"{sum(r['misses'] for r in rows)} misses in {total_q:,} reachable targets.",
        "",
        "| " + " | ".join(keys) + " |",
        "|---" * len(keys) + "|",
    ]
    lines += ["| " + " | ".join(str(row[k]) for k in keys) + " |" for row in rows]
    write_page("near_family.md", "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
