"""Adversarial reliability (issue 18): wrong answers, false "no", stray exceptions, repeatability.

Run: ``python -m benchmarks.adversarial [--arms ...] [--n-random 100000] [--n-singular 10000]
[--seed 0] [--quick] [--jobs 1]``; writes ``results/adversarial.md`` (``--quick``, 1/100 of the
sizes: ``results/adversarial_quick.md``) and the reproducers of every failure found
(at most :data:`KEEP` per class, arm and kind) as ``.json`` beside it. ``--jobs N`` runs N arms
at a time in separate processes; ``--classes`` and ``--no-bad-input`` select what runs. The full
run takes about 12 minutes in one process on a 2-core AMD EPYC (sawyer and gen3 are half of
it); ``--quick`` about 10 s. Sizes per arm: ``--n-random`` random poses, ``--n-singular``
branch-boundary poses plus a quarter as many at joint limits and (7-DOF, ``--n-line``) a tenth
as many next to psi's singular half-line, and 1/50 of ``--n-random`` for huge/tiny, threads
and repeated (1/1000 for layouts, each in about 12 layouts).

Every shipped arm (``om.arm_names()``) gets these attack classes; every answer marked ok is
checked against MuJoCo's own FK of the project's MJCF of the arm (``om.arm_model(arm)``,
``mj_kinematics`` on ``qpos = q``, the arm's end-effector site), not against ``arm.fk``:

* **random**: q uniform within limits (unlimited joints in [-pi, pi]), T = FK(q),
  c = configuration_of(q); ``solve`` without a hint, with the hint q + N(0, 0.05),
  ``solve_batch`` of all, ``solve_all`` (which must hold q). A false "no" is ok False, or an
  empty ``solve_all``.
* **singular**: q moved along one joint, within its limits, to a randomly drawn crossing so
  that a branch quantity (``om.ik.families.branch_values``, index 0, 1, 2) is +-10**u, u
  uniform in [-14, -3]; and joints at their limits +- 1e-12. Then ``solve``, hinted ``solve``
  and ``solve_all`` in c = configuration_of(q). Also "the other side": the flipped sign where
  |offset| <= ``om_redundant.ik.BRANCH_BAND`` (1e-7), where the pose belongs to both
  configurations.
* **huge/tiny**: hints of magnitude 1e3 ... 1e300; psi + 2 pi k for huge k (the same answer as
  for ``math.remainder(psi, 2 pi)``); poses translated by 1e3 ... 1e300 m (ok False,
  "unreachable"); translations changed by 1e-300 (a reachable pose) or of size 1e-300.
* **layouts**: Fortran-order, read-only, strided, big-endian and list inputs for T, q_hint,
  batch signs and redundancy: identical answers to the C-order call.
* **threads**: 4 threads sharing one solver agree bit for bit with serial calls;
  ``solve_batch`` equals per-row ``solve``.
* **repeated**: the same questions (random, near-singular, other branches, hinted,
  ``solve_all``, batch rows) asked again in random order, each after another call.
* **bad input** (:mod:`benchmarks.bad_input`): items 5 to 9 of the issue; the exception
  raised and whether it is an ``om.OMError``; for the command, in a subprocess, the exit
  status and the lines on stderr.

An ok answer is **wrong** if MuJoCo's FK differs from T by more than 1e-10 m or 1e-10 rad,
or q is not in the requested configuration (``OMSolver.holds``: signs equal, a branch quantity
within ``om_redundant.ik.BRANCH_BAND`` of zero counting for both; psi, read in the requested ELBOW branch,
within 1e-9 modulo 2 pi or within its own rounding next to its singular half-line), or
``within_limits`` is not
``lower <= q <= upper``. A **non-library exception** is anything raised that is not an
``om.OMError``.
"""

# The package, one module per idea: records (tolerances, tallies, failures), checker (MuJoCo's FK),
# answers (bit-for-bit keys, batch rows), draws and arm_run (one arm's run), one module per attack
# class (random_poses, singular, huge_tiny, layouts, threads and repeated with their questions),
# runner (sizes, run_arm), page (the Markdown) and cli (main, combine); __main__ runs main(). Here:
# the names that tests and other benchmarks use, and the records that --save-results pickles.

from __future__ import annotations

from .answers import flipped
from .arm_run import ArmRun
from .cli import combine, main
from .huge_tiny import run_huge_tiny
from .layouts import run_layouts
from .page import markdown, reproducer
from .random_poses import run_random
from .records import CLASSES, ArmResult, Failure, Tally
from .repeated import run_repeated
from .runner import Sizes, run_arm
from .singular import run_singular
from .threads import run_threads

__all__ = [
    "CLASSES",
    "ArmResult",
    "ArmRun",
    "Failure",
    "Sizes",
    "Tally",
    "combine",
    "flipped",
    "main",
    "markdown",
    "reproducer",
    "run_arm",
    "run_huge_tiny",
    "run_layouts",
    "run_random",
    "run_repeated",
    "run_singular",
    "run_threads",
]
