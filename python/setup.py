"""Packages what CMake builds into build/python (the _inscribe extension, the package's .py and
.pyi files): builds the `inscribe_python` target first, configuring the build directory when
it is not yet. INSCRIBE_BUILD_DIR overrides the build directory (default: build/ at the top of
the source tree). For Debian's /usr/bin/python3 only."""

import os
import pathlib
import re
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent
TOP = HERE.parent
BUILD = pathlib.Path(os.environ.get("INSCRIBE_BUILD_DIR", TOP / "build")).resolve()
VERSION = re.search(r"project\(inscribe VERSION ([0-9.]+)",
                    (TOP / "CMakeLists.txt").read_text()).group(1)


class BuildWithCMake(build_py):
    def run(self):
        if sys.executable != "/usr/bin/python3":
            raise SystemExit(f"inscribe is built for Debian's /usr/bin/python3, not {sys.executable}")
        if not (BUILD / "CMakeCache.txt").exists():
            subprocess.check_call(["cmake", "-S", str(TOP), "-B", str(BUILD),
                                   "-DCMAKE_BUILD_TYPE=RelWithDebInfo"])
        subprocess.check_call(["cmake", "--build", str(BUILD), "--target", "inscribe_python",
                               "-j2"])
        super().run()


setup(
    name="inscribe",
    version=VERSION,
    description="Unions of spheres approximating closed triangle meshes: the core in-process "
                "and the inscribed service",
    python_requires=">=3.11",
    packages=["inscribe"],
    package_dir={"": os.path.relpath(BUILD / "python", HERE)},
    package_data={"inscribe": ["_inscribe*.so", "*.pyi", "py.typed"]},
    cmdclass={"build_py": BuildWithCMake},
    zip_safe=False,
)
