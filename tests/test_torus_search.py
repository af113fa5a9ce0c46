"""The bounded search on the torus (csrc/ik/torus.c): Newton runs that come next to a root found
give up there (a root found already), except next to a near-double root, whose partner they may
be the only ones to reach."""

from __future__ import annotations

import numpy as np

import om_redundant as om
from om_redundant.kinematics import KinematicChain
from tests.conftest import distance

RIGHT = np.pi / 2
# One of a pair of roots 1.8e-5 rad apart on talos_left_arm (one of 10,000 random q of
# menagerie_humanoids).
NEAR_DOUBLE_Q = np.array(
    [-0.96178176180133, 0.14598407785565, 0.14171836349243, -0.09523489131336, 0.94303760990572,
     -1.04427749028461, -0.47181656123129]
)  # fmt: skip


def talos_left_arm() -> om.Arm:
    """PAL Talos's left arm (Menagerie's talos.xml from torso_2_link, DH rows to the micrometre,
    no tool): shoulder offsets a1 and a3, a torus arm of the exact family."""
    rows = (
        om.DHRow(a=0.1365, alpha=RIGHT, d=0.27873, theta=RIGHT),
        om.DHRow(a=0.0, alpha=-RIGHT, d=0.00493, theta=0.0),
        om.DHRow(a=0.02, alpha=-RIGHT, d=-0.2782, theta=-RIGHT),
        om.DHRow(a=-0.02, alpha=RIGHT, d=0.0, theta=0.0),
        om.DHRow(a=0.0, alpha=RIGHT, d=-0.2643, theta=RIGHT),
        om.DHRow(a=0.0, alpha=-RIGHT, d=0.0, theta=-RIGHT),
        om.DHRow(a=0.0, alpha=0.0, d=0.0, theta=0.0),
    )
    base = np.eye(4)
    base[1, 3] = 0.1575
    return om.Arm(
        name="talos-left",
        chain=KinematicChain(rows, base, np.eye(4)),
        joint_names=tuple(f"arm_left_{k}_joint" for k in range(1, 8)),
        lower=np.array([-1.5708, 0.00872665, -2.42601, -2.23402, -2.51327, -1.37008, -0.680678]),
        upper=np.array([0.785398, 2.87107, 2.42601, -0.00349066, 2.51327, 1.37008, 0.680678]),
    )


def test_a_near_double_root_keeps_its_partner():
    """At a fold of the psi-constrained map (the Jacobian's smallest singular value 2.4e-4) two
    roots of (T, c) lie 1.8e-5 rad apart; solve_all holds both, q among them (a run that gave up
    within 1e-3 of the first root lost the second)."""
    arm = talos_left_arm()
    solver = om.OMSolver(arm)
    q = NEAR_DOUBLE_Q
    T, c = arm.fk(q), solver.configuration_of(q)
    roots = solver.solve_all(T, c)
    assert any(distance(arm, root.q, q) < 1e-7 for root in roots)
    pair = [root for root in roots if distance(arm, root.q, q) < 1e-4]
    assert len(pair) == 2
    for root in pair:
        assert np.abs(arm.fk(root.q) - T).max() <= 1e-10 and solver.holds(root.q, c)


def test_a_hint_next_to_a_near_double_root_gets_the_nearer_of_the_pair():
    """The pair above, a hint 0.002 rad from q (a control tick of menagerie_humanoids) whose local
    solve finds q's partner, 2.0e-3 + 1.1e-5 rad from the hint: the window's fold-partner search
    reaches q (a deflated run that ends next to the partner, its residual's rounding lifted by
    deflation above the tolerance, is finished undeflated), and the hinted solve and the tick
    return it."""
    arm = talos_left_arm()
    solver = om.OMSolver(arm)
    q = NEAR_DOUBLE_Q
    hint = np.array(
        [-0.96170099364626, 0.14546890135626, 0.14039532699437, -0.0945963326009, 0.94281500145288,
         -1.0439861826986, -0.47061844928234]
    )  # fmt: skip
    T, c = arm.fk(q), solver.configuration_of(q)
    assert len([root for root in solver.solve_all(T, c) if distance(arm, root.q, q) < 1e-4]) == 2
    for answer in (solver.solve(T, c, q_hint=hint), solver.solve_from(T, c, hint)):
        assert answer.ok and distance(arm, answer.q, q) < 1e-9
