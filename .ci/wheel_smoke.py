"""The installed wheel's smoke test (.ci/wheel, and cibuildwheel's test-command): the package
imports from site-packages with its compiled core, solves, runs the README's first example,
and passes a few of the checkout's tests, copied into a scratch directory so that the installed
package (not the checkout's sources) is the one they import.

Usage: python .ci/wheel_smoke.py PROJECT_DIR
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

#: The tests run against the installed wheel: solves, the binding's safety and its fuzz test.
TESTS = ["tests/test_solver.py", "tests/test_binding_safety.py", "tests/test_binding_fuzz.py"]


def main(project: Path) -> None:
    """Run the smoke test against the wheel installed in this interpreter's environment."""
    with tempfile.TemporaryDirectory() as scratch:
        work = Path(scratch)
        check = (
            "import sys, numpy as np, om_redundant as om\n"
            "from om_redundant import _core\n"
            "built = _core.ckernels.__file__\n"
            f"assert built.startswith({sysconfig.get_paths()['purelib']!r}), built\n"
            "solver = om.OMSolver('panda')\n"
            "q = np.array([0.3, -0.4, 0.2, -2.2, 0.3, 1.9, 0.6])\n"
            "solution = solver.solve(solver.arm.fk(q), solver.configuration_of(q))\n"
            "assert solution.ok and np.allclose(solution.q, q), solution\n"
            "print('installed:', built)\n"
        )
        readme = (project / "README.md").read_text()
        example = re.search(r"```python\n(.*?)```", readme, re.DOTALL)
        assert example, "README.md has no python example"
        for script in (check, example.group(1)):
            subprocess.run([sys.executable, "-c", script], cwd=work, check=True)
        for folder in ("tests", "benchmarks"):
            shutil.copytree(project / folder, work / folder)
        shutil.copy(project / "pyproject.toml", work)  # pytest's settings
        command = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-n", "2", *TESTS]
        subprocess.run(command, cwd=work, check=True)


if __name__ == "__main__":
    main(Path(sys.argv[1]).resolve())
