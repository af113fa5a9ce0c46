"""Builds om_redundant's compiled core (csrc/, the C extension om_redundant.ckernels); the
rest of the project's metadata is in pyproject.toml."""

from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

# IEEE arithmetic as written: no fused multiply-add (results stay bit-identical across
# machines), no fast-math; errno is not needed, which lets sqrt inline. Hidden visibility:
# only PyInit_ckernels is exported, so calls within the extension are direct and may be
# inlined (an exported function could be interposed; ~3 % fewer instructions per solve).
_UNIX_FLAGS = [
    "-std=c11",
    "-O3",
    "-fvisibility=hidden",
    "-ffp-contract=off",
    "-fno-math-errno",
    "-Wno-unused-parameter",
]


class BuildExt(build_ext):
    def build_extensions(self) -> None:
        if self.compiler.compiler_type == "msvc":
            flags = ["/O2", "/fp:precise"]
        else:
            flags = _UNIX_FLAGS
        for extension in self.extensions:
            extension.extra_compile_args = flags
        super().build_extensions()


setup(
    ext_modules=[
        Extension(
            "om_redundant.ckernels",
            sources=sorted(str(path) for path in Path("csrc").rglob("*.c")),
            include_dirs=["csrc/ik", "csrc/redundancy", "csrc/binding"],
            depends=sorted(str(path) for path in Path("csrc").rglob("*.h")),
        )
    ],
    cmdclass={"build_ext": BuildExt},
)
