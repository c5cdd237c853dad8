"""The inscribe package's PEP 517 build backend: plain Python, nothing from any registry.

pip (with or without build isolation) calls build_wheel in the interpreter it installs for.
The wheel holds what CMake assembles in <build>/python/inscribe (the _inscribe extension built
for that interpreter, the package's .py and .pyi files, _version.py with the top
CMakeLists.txt's project VERSION); only the `inscribe_python` target is built.

The build directory, in this order:
  - INSCRIBE_BUILD_DIR when set (configured here when it is not yet; refused when it is
    configured for an interpreter whose extensions another one cannot load);
  - build/ at the top of the source tree when it is configured with the Python package for an
    interpreter with this one's extension suffix (EXT_SUFFIX, e.g.
    .cpython-311-x86_64-linux-gnu.so): the extension built there loads here;
  - else build/python-<SOABI>, configured here for this interpreter, CMAKE_BUILD_TYPE Release
    (INSCRIBE_BUILD_TYPE overrides), without tests and benchmarks.
CMAKE_BUILD_PARALLEL_LEVEL sets the build's parallelism (default: every core). The wheel's
extension has its debug information stripped (`strip --strip-debug`, binutils; a
RelWithDebInfo build's 240 MB are 9 MB without it); an editable install imports the build
folder's, debug information and all.
Needs cmake, a C++17 compiler and the C++ dependencies (scripts/install-deps) on the machine.
"""

import base64
import hashlib
import os
import pathlib
import re
import subprocess
import shutil
import sys
import sysconfig
import tempfile
import zipfile

HERE = pathlib.Path(__file__).resolve().parent.parent  # python/
TOP = HERE.parent                                      # the source tree
NAME = "inscribe"
SUMMARY = ("Unions of spheres approximating closed triangle meshes: the core in-process and "
           "the inscribed service")
REQUIRES_PYTHON = ">=3.9"
# numpy for every array; grpcio for inscribe.Client only (imported when Client is first used).
REQUIRES_DIST = ["numpy>=1.21", 'grpcio>=1.30; extra == "client"']
PROVIDES_EXTRA = ["client"]
PACKAGE_FILES = re.compile(r"[A-Za-z_]+\.pyi?|py\.typed")


class BuildError(RuntimeError):
    """A build that cannot go on, with what to do about it."""


def _interpreter_for_cmake():
    """The interpreter CMake finds headers for: a venv's base interpreter (a venv's own python
    may be deleted while its build folder stays), else this one."""
    base = getattr(sys, "_base_executable", "")
    return base if base and os.path.exists(base) else sys.executable


def _cache_entry(build, name):
    cache = build / "CMakeCache.txt"
    if not cache.exists():
        return None
    match = re.search(rf"^{name}:[A-Z]+=(.*)$", cache.read_text(errors="replace"), re.M)
    return match.group(1) if match else None


def _ext_suffix_of(python):
    """EXT_SUFFIX of another interpreter, or None when it does not run."""
    try:
        return subprocess.run(
            [python, "-c", "import sysconfig; print(sysconfig.get_config_var('EXT_SUFFIX'))"],
            check=True, capture_output=True, text=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def _python_of(build):
    """The interpreter `build` is configured to build the package for, or None when it is not
    configured with the package."""
    if _cache_entry(build, "INSCRIBE_BUILD_PYTHON") not in ("ON", "TRUE", "1"):
        return None
    return _cache_entry(build, "INSCRIBE_PYTHON")


def build_directory():
    """The build directory (see the module's docstring) and whether it must be configured."""
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    given = os.environ.get("INSCRIBE_BUILD_DIR")
    if given:
        build = pathlib.Path(given).resolve()
        if not (build / "CMakeCache.txt").exists():
            return build, True
        python = _python_of(build)
        if python is None:
            raise BuildError(f"INSCRIBE_BUILD_DIR={build} is configured without the Python "
                             "package: reconfigure it with -DINSCRIBE_BUILD_PYTHON=ON, or unset "
                             "INSCRIBE_BUILD_DIR")
        theirs = _ext_suffix_of(python)
        if theirs != suffix:
            raise BuildError(
                f"INSCRIBE_BUILD_DIR={build} builds for {python} (extension suffix {theirs}), "
                f"which {sys.executable} ({suffix}) cannot load: reconfigure it with "
                f"-DINSCRIBE_PYTHON={_interpreter_for_cmake()}, or unset INSCRIBE_BUILD_DIR")
        return build, False
    default = TOP / "build"
    python = _python_of(default)
    if python is not None and _ext_suffix_of(python) == suffix:
        return default, False
    build = default / f"python-{sysconfig.get_config_var('SOABI')}"
    return build, not (build / "CMakeCache.txt").exists()


def _run(command):
    print("inscribe build:", " ".join(command), file=sys.stderr, flush=True)
    try:
        subprocess.run(command, check=True)
    except FileNotFoundError:
        raise BuildError(f"{command[0]} not found: install cmake and inscribe's C++ "
                         "dependencies first (scripts/install-deps)") from None
    except subprocess.CalledProcessError as error:
        raise BuildError(f"{' '.join(command)} failed (exit {error.returncode}); its output "
                         "is above (pip install -v shows it)") from None


def build_package():
    """Builds the inscribe_python target for this interpreter; returns <build>/python/inscribe."""
    if not (TOP / "CMakeLists.txt").exists():
        raise BuildError(f"{HERE} is not inside inscribe's source tree (no {TOP}/CMakeLists.txt): "
                         "pip older than 21.3 copies the folder away; upgrade pip, or install "
                         "from the source tree")
    build, configure = build_directory()
    if configure:
        _run(["cmake", "-S", str(TOP), "-B", str(build),
              f"-DCMAKE_BUILD_TYPE={os.environ.get('INSCRIBE_BUILD_TYPE', 'Release')}",
              f"-DINSCRIBE_PYTHON={_interpreter_for_cmake()}", "-DINSCRIBE_BUILD_PYTHON=ON",
              "-DINSCRIBE_BUILD_TESTS=OFF", "-DINSCRIBE_BUILD_BENCH=OFF"])
    parallel = [] if "CMAKE_BUILD_PARALLEL_LEVEL" in os.environ else [str(os.cpu_count() or 1)]
    _run(["cmake", "--build", str(build), "--target", "inscribe_python", "--parallel", *parallel])
    package = build / "python" / NAME
    extension = package / f"_inscribe{sysconfig.get_config_var('EXT_SUFFIX')}"
    if not extension.exists():
        raise BuildError(f"the build gave no {extension}: {build} builds for another "
                         "interpreter (see INSCRIBE_BUILD_DIR)")
    return package


def without_debug_information(extension):
    """The extension's bytes without debug sections (strip --strip-debug), or as they are
    when binutils' strip is not there."""
    strip = shutil.which("strip")
    if strip is None:
        return extension.read_bytes()
    with tempfile.TemporaryDirectory() as scratch:
        stripped = pathlib.Path(scratch) / extension.name
        _run([strip, "--strip-debug", "-o", str(stripped), str(extension)])
        return stripped.read_bytes()


def version_of(package):
    """The version CMake wrote into _version.py (the top CMakeLists.txt's project VERSION)."""
    text = (package / "_version.py").read_text()
    return re.search(r'^__version__ = "([^"]+)"$', text, re.M).group(1)


def wheel_tag():
    """The wheel's interpreter-abi-platform tag, as pip's `packaging.tags` computes the most
    specific tag for this interpreter (CPython: cpXY-cpXY[t][d]; others: their SOABI)."""
    version = f"{sys.version_info.major}{sys.version_info.minor}"
    platform = re.sub(r"[-.]", "_", sysconfig.get_platform())
    if sys.implementation.name == "cpython":
        abi = f"cp{version}"
        if sysconfig.get_config_var("Py_GIL_DISABLED"):
            abi += "t"
        if sysconfig.get_config_var("Py_DEBUG"):
            abi += "d"
        return f"cp{version}-{abi}-{platform}"
    soabi = re.sub(r"[-.]", "_", sysconfig.get_config_var("SOABI") or "none")
    short = {"pypy": "pp"}.get(sys.implementation.name, sys.implementation.name)
    return f"{short}{version}-{soabi}-{platform}"


def _metadata(version):
    lines = ["Metadata-Version: 2.1", f"Name: {NAME}", f"Version: {version}",
             f"Summary: {SUMMARY}", f"Requires-Python: {REQUIRES_PYTHON}"]
    lines += [f"Requires-Dist: {requirement}" for requirement in REQUIRES_DIST]
    lines += [f"Provides-Extra: {extra}" for extra in PROVIDES_EXTRA]
    readme = TOP / "docs" / "python.md"
    if readme.exists():
        lines += ["Description-Content-Type: text/markdown", "", readme.read_text()]
    return "\n".join(lines) + "\n"


def _record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def write_wheel(directory, files, version, tag):
    """A wheel of `files` ({path in the wheel: bytes}) and its .dist-info; returns its name."""
    dist_info = f"{NAME}-{version}.dist-info"
    files = dict(files)
    files[f"{dist_info}/METADATA"] = _metadata(version).encode()
    files[f"{dist_info}/WHEEL"] = ("Wheel-Version: 1.0\nGenerator: inscribe_build\n"
                                   f"Root-Is-Purelib: false\nTag: {tag}\n").encode()
    files[f"{dist_info}/top_level.txt"] = f"{NAME}\n".encode()
    record = [_record_line(name, data) for name, data in files.items()]
    files[f"{dist_info}/RECORD"] = ("\n".join(record + [f"{dist_info}/RECORD,,"]) + "\n").encode()
    name = f"{NAME}-{version}-{tag}.whl"
    with zipfile.ZipFile(pathlib.Path(directory) / name, "w", zipfile.ZIP_DEFLATED) as wheel:
        for path, data in files.items():
            info = zipfile.ZipInfo(path, date_time=(2020, 1, 1, 0, 0, 0))
            info.external_attr = (0o755 if path.endswith(".so") else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            wheel.writestr(info, data)
    return name


# ---- PEP 517 and PEP 660 hooks -------------------------------------------------------------

def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_editable(config_settings=None):
    return []


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    package = build_package()
    extension = f"_inscribe{sysconfig.get_config_var('EXT_SUFFIX')}"
    files = {f"{NAME}/{path.name}": path.read_bytes() for path in sorted(package.iterdir())
             if PACKAGE_FILES.fullmatch(path.name)}
    files[f"{NAME}/{extension}"] = without_debug_information(package / extension)
    return write_wheel(wheel_directory, files, version_of(package), wheel_tag())


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    """An editable install: a .pth naming <build>/python, so the environment imports the build
    folder's package; `cmake --build <build> --target inscribe_python` refreshes it."""
    package = build_package()
    pth = f"{package.parent}\n".encode()
    return write_wheel(wheel_directory, {f"_{NAME}_editable.pth": pth}, version_of(package),
                       wheel_tag())


if __name__ == "__main__":
    # `python3 build_backend/inscribe_build.py DIR`: build a wheel into DIR, for trying out.
    target = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    target.mkdir(parents=True, exist_ok=True)
    print(target / build_wheel(str(target)))
