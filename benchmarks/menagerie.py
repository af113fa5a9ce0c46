"""Arms brought by their MuJoCo models: every reference Menagerie arm imported and solved.

Run: ``python -m benchmarks.menagerie [--n 10000] [--seed 0] [--extra DIR]``; writes
``results/menagerie.md``. For each arm in ``../shared/reference/menagerie`` (kinematics-only
copies of MuJoCo Menagerie models) and, with ``--extra DIR``, each arm of ``EXTRA`` whose
model file is present under DIR (kinematics-only MJCF text of further Menagerie models, kept
outside the project; absent files are skipped): ``om.arm_from_mujoco`` imports it, ``check-model``'s
comparison measures the arm file against the model over 1,000 random q, and where
``OMSolver`` accepts the arm, N random in-limit q are solved against MuJoCo's OWN frame pose
(``mj_kinematics`` of the Menagerie model at qpos = q): q among ``solve_all(T, c)`` with c its
configuration, every root reaching T (1e-10 m, 1e-10 rad, MuJoCo's FK) in configuration c,
and the hinted solve returning q or a root nearer the hint. An arm OMSolver refuses is listed
with its ModelError.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import NamedTuple

import mujoco
import numpy as np

import om_redundant as om
from om_redundant.mujoco_io.frames import arm_frame_names, find_frame

from .report import write_page
from .robots import joint_distance

MENAGERIE = Path(__file__).resolve().parents[2] / "shared" / "reference" / "menagerie"


class Entry(NamedTuple):
    """Where an arm is in a Menagerie model: file, frame and the chain's prefix and root."""

    path: str
    frame: str
    frame_type: str
    prefix: str = ""
    root: str | None = None


#: The reference copies in ``MENAGERIE``.
REFERENCE = {
    "panda_nohand": Entry("franka_emika_panda/panda_nohand.xml", "attachment_site", "site"),
    "fr3": Entry("franka_fr3/fr3.xml", "attachment_site", "site"),
    "iiwa14": Entry("kuka_iiwa_14/iiwa14.xml", "attachment_site", "site"),
    "gen3": Entry("kinova_gen3/gen3.xml", "pinch_site", "site"),
    "xarm7_nohand": Entry("ufactory_xarm7/xarm7_nohand.xml", "attachment_site", "site"),
    "sawyer": Entry("rethink_robotics_sawyer/sawyer.xml", "attachment_site", "site"),
    "ur5e": Entry("universal_robots_ur5e/ur5e.xml", "wrist_3_link", "body"),
    "ur10e": Entry("universal_robots_ur10e/ur10e.xml", "attachment_site", "site"),
    "flexiv_rizon4": Entry("flexiv_rizon4/flexiv_rizon4.xml", "link7", "body"),
    "wx250s": Entry("trossen_wx250s/wx250s.xml", "wx250s/gripper_link", "body"),
    "piper": Entry("agilex_piper/piper.xml", "link6", "body"),
    "lite6": Entry("ufactory_lite6/lite6.xml", "attachment_site", "site"),
}

#: Further Menagerie arms, measured with ``--extra DIR`` when DIR holds their model files
#: (the kinematic MJCF text of google-deepmind/mujoco_menagerie, meshes and inertials dropped).
EXTRA = {
    "m1013": Entry("doosan_robotics_m1013/m1013.xml", "link_6", "body"),
    "fr3v2": Entry("franka_fr3_v2/fr3v2.xml", "fr3v2_link8", "body"),
    "flexiv_rizon4s": Entry("flexiv_rizon4s/flexiv_rizon4s.xml", "link7", "body"),
    "gen3_lite": Entry("kinova_gen3_lite/gen3_lite.xml", "ee_site", "site"),
    "arx_l5": Entry("arx_l5/arx_l5.xml", "link6", "body"),
    "z1": Entry("unitree_z1/z1.xml", "link06", "body"),
    "yam": Entry("i2rt_yam/yam.xml", "grasp_site", "site"),
}


def import_arm(entry: Entry, folder: Path = MENAGERIE) -> tuple[om.Arm, mujoco.MjModel]:
    """The imported arm of a Menagerie model under ``folder``, and the model (meshes skipped)."""
    path = folder / entry.path
    arm = om.arm_from_mujoco(path, entry.frame, entry.frame_type, entry.prefix, entry.root)
    return arm, om.load_mujoco_model(path)


def frame_pose(model: mujoco.MjModel, data: mujoco.MjData, arm: om.Arm, q: np.ndarray) -> np.ndarray:
    """MuJoCo's own pose of the arm's frame at qpos = q (other joints, e.g. fingers, at qpos0), in
    the frame of the arm's root body (its prefix and root as the arm file keeps them)."""
    ids = [model.joint(arm.prefix + n).id for n in arm.joint_names]
    data.qpos[:] = model.qpos0
    data.qpos[model.jnt_qposadr[ids]] = q
    mujoco.mj_kinematics(model, data)
    frame_id, _ = find_frame(model, arm.frame_type, arm_frame_names(arm.frame_name, arm.prefix))
    frame = data.site(frame_id) if arm.frame_type == "site" else data.body(frame_id)
    root = data.body(arm.root or "world")
    R_root = root.xmat.reshape(3, 3)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R_root.T @ frame.xmat.reshape(3, 3), R_root.T @ (frame.xpos - root.xpos)
    return T


def _random_q(arm: om.Arm, n: int, rng: np.random.Generator) -> np.ndarray:
    lower = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    upper = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return rng.uniform(lower, upper, (n, arm.dof))


def _angle(R: np.ndarray, S: np.ndarray) -> float:
    E = R.T @ S
    s = 0.5 * np.linalg.norm([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]])
    return float(np.arctan2(s, 0.5 * (np.trace(E) - 1.0)))


def measure(
    name: str,
    n: int,
    seed: int,
    entry: Entry | None = None,
    folder: Path = MENAGERIE,
    *,
    times: bool = False,
) -> dict:
    """One arm's row: import, check-model, acceptance and the exact solves.

    Args:
        name: The arm's name in the row (and its key in ``REFERENCE`` without ``entry``).
        n: Random in-limit joint vectors solved.
        seed: Seed of those joint vectors.
        entry: Where the arm is; default ``REFERENCE[name]``.
        folder: The folder ``entry.path`` is under.
        times: Also the median wall time of one ``solve_all(T, c)``, of one hinted
            ``solve(T, c, q_hint=q)`` and of one control tick, ``solve_from(T, c, q_previous)``
            from joints 0.002 rad back from q (a random direction), over the n targets; and how
            often the tick returns q.

    Returns:
        The row: a column per quantity measured; an arm OMSolver refuses has its ModelError.
    """
    entry = entry or REFERENCE[name]
    arm, model = import_arm(entry, folder)
    row: dict = {"arm": name, "model": entry.path, "dof": arm.dof}
    comparison = om.compare_mujoco_model(arm, model, samples=1000)
    row["check-model"] = f"{comparison.max_position_error:.1e} m / {comparison.max_orientation_error:.1e} rad"
    try:
        solver = om.OMSolver(arm)
    except om.ModelError as error:
        row["solver"] = f"refused: {error}"
        return row
    near = ", near: its nominal arm" if solver.nominal is not None else ""
    row["solver"] = f"accepted ({solver.model_arm.family_name.split(':')[0]}{near})"
    data = mujoco.MjData(model)
    among = hinted = nearer = wrong = roots_total = 0
    worst_position = worst_orientation = 0.0
    all_times, solve_times, tick_times, ticks = [], [], [], 0
    directions = np.random.default_rng(seed + 1)  # (the ticks' own draws: the q are the same without them)
    start = time.perf_counter()
    for q in _random_q(arm, n, np.random.default_rng(seed)):
        T = frame_pose(model, data, arm, q)
        c = solver.configuration_of(q)
        tic = time.perf_counter()
        roots = solver.solve_all(T, c)
        all_times.append(time.perf_counter() - tic)
        roots_total += len(roots)
        among += any(joint_distance(arm, r.q, q) < 1e-7 for r in roots)
        for root in roots:
            reached = frame_pose(model, data, arm, root.q)
            position = float(np.linalg.norm(reached[:3, 3] - T[:3, 3]))
            orientation = _angle(T[:3, :3], reached[:3, :3])
            worst_position, worst_orientation = (
                max(worst_position, position),
                max(worst_orientation, orientation),
            )
            wrong += position > 1e-10 or orientation > 1e-10 or not solver.configuration_of(root.q).isclose(c)
        tic = time.perf_counter()
        sol = solver.solve(T, c, q_hint=q)
        solve_times.append(time.perf_counter() - tic)
        if sol.ok and joint_distance(arm, sol.q, q) < 1e-7:
            hinted += 1
        elif sol.ok:
            nearer += (
                float(np.linalg.norm(sol.q - q))
                <= min((float(np.linalg.norm(r.q - q)) for r in roots), default=np.inf) + 1e-9
            )
        if times:
            back = directions.normal(size=arm.dof)
            q_previous = q - 0.002 * back / np.linalg.norm(back)
            tic = time.perf_counter()
            tick = solver.solve_from(T, c, q_previous)
            tick_times.append(time.perf_counter() - tic)
            ticks += tick.ok and joint_distance(arm, tick.q, q) < 1e-7
    row.update(
        {
            "q among solve_all": f"{100 * among / n:.3f} %",
            "hinted solve returns q": f"{100 * hinted / n:.3f} %",
            "... or a nearer root": f"{100 * (hinted + nearer) / n:.3f} %",
            "roots per (pose, c)": f"{roots_total / n:.3f}",
            "roots not exact or not in c": str(wrong),
            "max error (MuJoCo's FK)": f"{worst_position:.1e} m / {worst_orientation:.1e} rad",
            "s": f"{time.perf_counter() - start:.0f}",
        }
    )
    if times:
        row["solve (hinted), median"] = _duration(float(np.median(solve_times)))
        row["a tick (solve_from), median"] = _duration(float(np.median(tick_times)))
        row["the tick returns q"] = f"{100 * ticks / n:.3f} %"
        row["solve_all, median"] = _duration(float(np.median(all_times)))
    return row


def _duration(seconds: float) -> str:
    return f"{1e6 * seconds:.0f} µs" if seconds < 1e-3 else f"{1e3 * seconds:.1f} ms"


def import_row(name: str, entry: Entry, n: int, seed: int, folder: Path, **options: bool) -> dict:
    """The arm's row of :func:`measure` after an ``import`` column, or where the arm does not
    import (its file does not load, a frame or joint the importer refuses), why.

    Args:
        name: The arm's name in the row.
        entry: Where the arm is under ``folder``.
        n: Random in-limit joint vectors solved.
        seed: Seed of those joint vectors.
        folder: The folder ``entry.path`` is under.
        **options: Keyword options of :func:`measure` (``times``).

    Returns:
        The row.
    """
    try:
        measured = measure(name, n, seed, entry, folder, **options)
    except om.OMError as error:
        return {"arm": name, "import": f"failed: {error}"}
    return {"arm": name, "import": "yes", **measured}


def files_arguments(doc: str, arms: dict[str, Entry], folder: str, n: int) -> argparse.Namespace:
    """The command line of a benchmark over arms' model files kept outside the project: --dir
    (the folder holding ``folder``), --n (random joint vectors per accepted arm, default n),
    --seed, --arms (some of ``arms``)."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--dir", type=Path, required=True, help=f"folder holding {folder}")
    parser.add_argument("--n", type=int, default=n, help="random joint vectors per accepted arm")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--arms", nargs="+", choices=list(arms))
    return parser.parse_args()


def present(arms: dict[str, Entry], folder: Path, names: list[str] | None = None) -> list[str]:
    """The names (of ``names``, default every arm) whose model file ``folder`` holds; each other
    one is skipped with a note, so a benchmark runs where the models are not at hand (CI)."""
    kept = []
    for name in names or list(arms):
        if (folder / arms[name].path).is_file():
            kept.append(name)
        else:
            print(f"{name}: {folder / arms[name].path} absent, skipped", flush=True)
    return kept


def available(extra: Path | None = None) -> dict[str, tuple[Entry, Path]]:
    """The arms to measure and their folders: every reference arm, and EXTRA's present in ``extra``.

    An EXTRA arm whose model file is absent from ``extra`` (or every one, without ``extra``) is
    skipped with a note, so the benchmark runs where Menagerie is not at hand (CI).
    """
    arms = {name: (entry, MENAGERIE) for name, entry in REFERENCE.items()}
    if extra is not None:
        arms.update({name: (EXTRA[name], extra) for name in present(EXTRA, extra)})
    return arms


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000, help="random joint vectors per arm")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--extra", type=Path, help="folder holding EXTRA's model files")
    parser.add_argument("--arms", nargs="+", choices=[*REFERENCE, *EXTRA])
    args = parser.parse_args()
    arms = available(args.extra)
    rows = []
    for name in args.arms or list(arms):
        if name not in arms:
            print(f"{name}: not available (give --extra DIR with its model file)", flush=True)
            continue
        rows.append(measure(name, args.n, args.seed, *arms[name]))
        print(rows[-1], flush=True)
    title = f"# Menagerie arms imported and solved ({args.n:,} random q per accepted arm, seed {args.seed})"
    write_page("menagerie.md", "\n".join([title, "", *table(rows, ("model", "dof"))]) + "\n")


def table(rows: list[dict], hidden: tuple[str, ...] = ()) -> list[str]:
    """The rows as a Markdown table, one column per key any row has (but ``hidden``), "-" where
    a row has none."""
    keys = list(dict.fromkeys(k for row in rows for k in row if k not in hidden))
    lines = ["| " + " | ".join(keys) + " |", "|---" * len(keys) + "|"]
    for row in rows:
        lines.append("| " + " | ".join(str(row.get(k, "-")).replace("|", "\\|") for k in keys) + " |")
    return lines


if __name__ == "__main__":
    main()
