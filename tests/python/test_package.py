"""`pip install ./python` as users run it: into a fresh bare venv (nothing but pip), into a
venv seeing Debian's numpy, with pyenv's interpreter; the wheel's tag as pip's own `packaging`
computes it; `import inscribe` without numpy or grpcio. Every install builds in this build
directory (INSCRIBE_BUILD_DIR), where inscribe_python is already up to date, and runs offline
(--no-index: this machine has no package index, so the bare venv also takes --no-deps)."""

import glob
import os
import pathlib
import re
import subprocess
import sys
import sysconfig

import pytest

from conftest import BUILD_DIR, SOURCE_DIR, mesh_path

DEBIAN_PYTHON = "/usr/bin/python3"
VERSION = re.search(r"project\(inscribe VERSION ([0-9.]+)",
                    (SOURCE_DIR / "CMakeLists.txt").read_text()).group(1)


def clean_environment(**extra):
    """This process's environment without the suite's PYTHONPATH (build/python), so a child
    imports what pip installed, building in BUILD_DIR on at most two cores."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.update(INSCRIBE_BUILD_DIR=str(BUILD_DIR), CMAKE_BUILD_PARALLEL_LEVEL="2",
               PIP_NO_INDEX="1", PIP_DISABLE_PIP_VERSION_CHECK="1", **extra)
    return env


def run(*command, cwd="/", **extra):
    result = subprocess.run([str(c) for c in command], capture_output=True, text=True, cwd=cwd,
                            env=clean_environment(**extra))
    if result.returncode != 0:
        raise AssertionError(f"{' '.join(map(str, command))} exited {result.returncode}:\n"
                             f"{result.stdout}\n{result.stderr}")
    return result.stdout


def make_venv(python, path, *flags):
    run(python, "-m", "venv", *flags, path)
    return path / "bin" / "python"


def pip_install(python, *flags):
    run(python, "-m", "pip", "install", "--quiet", *flags, SOURCE_DIR / "python")


def preferred_linux_tag(python):
    """The most specific tag pip's vendored `packaging` gives `python` for a wheel built
    against this machine's libraries (linux_<arch>: not manylinux, which promises
    portability)."""
    return run(python, "-c", "from pip._vendor.packaging import tags; print(next("
                             "t for t in tags.sys_tags() if t.platform.startswith('linux_')))"
               ).strip()


def test_a_bare_venv_installs_and_imports_without_numpy_or_grpcio(tmp_path):
    python = make_venv(DEBIAN_PYTHON, tmp_path / "bare")
    pip_install(python, "--no-build-isolation", "--no-deps")
    out = run(python, "-c", "import inscribe, sys; print(inscribe.__version__, inscribe.__file__, "
                            "'numpy' in sys.modules, 'grpc' in sys.modules)").split()
    assert out[0] == VERSION
    assert out[1].startswith(str(tmp_path / "bare" / "lib"))
    assert out[2:] == ["False", "False"]
    # The service client names what it lacks when it is asked for.
    script = ("import inscribe\ntry:\n    inscribe.Client\nexcept ImportError as e:\n"
              "    print(e)\n")
    assert "inscribe.Client needs grpcio, which is not installed: pip install grpcio" in \
        run(python, "-c", script)
    # The wheel's tag is the one pip prefers for a wheel of this machine; metadata is honest.
    dist_info = pathlib.Path(glob.glob(str(tmp_path / f"bare/lib/python3*/site-packages/"
                                           f"inscribe-{VERSION}.dist-info"))[0])
    tag = re.search(r"^Tag: (.*)$", (dist_info / "WHEEL").read_text(), re.M).group(1)
    assert tag == preferred_linux_tag(python)
    metadata = (dist_info / "METADATA").read_text()
    assert f"Version: {VERSION}\n" in metadata
    assert "Requires-Dist: numpy" in metadata
    assert 'Requires-Dist: grpcio>=1.30; extra == "client"' in metadata
    # RECORD lists every installed file with its hash (pip checks them on install).
    record = (dist_info / "RECORD").read_text()
    assert re.search(r"^inscribe/_inscribe\.cpython-[^,]+\.so,sha256=", record, re.M)
    # The installed extension carries no debug information (whatever the build type).
    extension = next(dist_info.parent.glob("inscribe/_inscribe.cpython-*.so"))
    assert b".debug_info" not in extension.read_bytes()


def test_pip_with_build_isolation_needs_nothing_from_an_index(tmp_path):
    python = make_venv(DEBIAN_PYTHON, tmp_path / "isolated")
    pip_install(python, "--no-deps")
    assert run(python, "-c", "import inscribe; print(inscribe.__version__)").strip() == VERSION


def test_an_editable_install_imports_the_build_folders_package(tmp_path):
    python = make_venv(DEBIAN_PYTHON, tmp_path / "editable")
    pip_install(python, "--no-build-isolation", "--no-deps", "--editable")
    where = run(python, "-c", "import inscribe; print(inscribe.__file__)").strip()
    assert where == str(BUILD_DIR.resolve() / "python" / "inscribe" / "__init__.py")


def test_a_system_site_packages_venv_generates_the_suites_spheres(tmp_path):
    import inscribe  # the suite's own, from build/python

    python = make_venv(DEBIAN_PYTHON, tmp_path / "system", "--system-site-packages")
    pip_install(python, "--no-build-isolation")  # numpy: Debian's python3-numpy satisfies it
    eight = mesh_path("eight.off")
    script = ("import inscribe, sys\n"
              f"s = inscribe.generate({eight!r}, max_spheres=40, evaluate=False)\n"
              "print(inscribe.__file__)\n"
              "print(s.spheres.tobytes().hex())\n")
    where, spheres = run(python, "-c", script).split()
    assert where.startswith(str(tmp_path / "system"))
    expected = inscribe.generate(inscribe.load_mesh(eight), max_spheres=40, evaluate=False)
    assert bytes.fromhex(spheres) == expected.spheres.tobytes()


def pyenv_python_for_this_build():
    """A pyenv interpreter whose extensions this build's extension is (its EXT_SUFFIX), or
    None."""
    root = pathlib.Path(os.environ.get("PYENV_ROOT", pathlib.Path.home() / ".pyenv"))
    suffix = sysconfig.get_config_var("EXT_SUFFIX")
    for python in sorted(root.glob("versions/*/bin/python3")):
        probe = subprocess.run([str(python), "-c", "import sysconfig; "
                                "print(sysconfig.get_config_var('EXT_SUFFIX'))"],
                               capture_output=True, text=True)
        if probe.returncode == 0 and probe.stdout.strip() == suffix:
            return python
    return None


def test_pyenvs_python_installs_into_its_own_venv(tmp_path):
    python = pyenv_python_for_this_build()
    if python is None:
        pytest.skip(f"no pyenv python3 with extension suffix "
                    f"{sysconfig.get_config_var('EXT_SUFFIX')} (another needs its own build "
                    "folder, a full core build)")
    venv_python = make_venv(python, tmp_path / "pyenv")
    pip_install(venv_python, "--no-build-isolation", "--no-deps")
    out = run(venv_python, "-c", "import inscribe, sys; print(sys.base_prefix, inscribe.__file__, "
                                 "inscribe.__version__)")
    assert out.split() == [str(python.parent.parent),
                           next(iter(glob.glob(str(tmp_path / "pyenv/lib/python3*/site-packages/"
                                                   "inscribe/__init__.py")))), VERSION]


def other_pythons():
    """pyenv interpreters with another extension suffix than this build's."""
    root = pathlib.Path(os.environ.get("PYENV_ROOT", pathlib.Path.home() / ".pyenv"))
    found = []
    for python in sorted(root.glob("versions/3.*/bin/python3")):
        probe = subprocess.run([str(python), "-c", "import sys, sysconfig; print(sys.version_info "
                                ">= (3, 9), sysconfig.get_config_var('EXT_SUFFIX'))"],
                               capture_output=True, text=True)
        fields = probe.stdout.split()
        if probe.returncode == 0 and fields[0] == "True" and \
                fields[1] != sysconfig.get_config_var("EXT_SUFFIX"):
            found.append(python)
    return found


def test_another_interpreter_gets_its_own_build_folder_and_tag():
    pythons = other_pythons()
    if not pythons:
        pytest.skip("no pyenv python3 (3.9+) with another extension suffix than this build's")
    for python in pythons:
        soabi = run(python, "-c", "import sysconfig; print(sysconfig.get_config_var('SOABI'))")
        env = clean_environment(PYTHONPATH=str(SOURCE_DIR / "python" / "build_backend"))
        # This build directory is configured for Debian's python3: refused by name ...
        result = subprocess.run(
            [str(python), "-c", "import inscribe_build; inscribe_build.build_directory()"],
            capture_output=True, text=True, env=env, cwd="/")
        assert result.returncode != 0
        assert f"INSCRIBE_BUILD_DIR={BUILD_DIR.resolve()} builds for" in result.stderr
        assert "-DINSCRIBE_PYTHON=" in result.stderr
        # ... and without INSCRIBE_BUILD_DIR the interpreter gets build/python-<SOABI>.
        del env["INSCRIBE_BUILD_DIR"]
        folder = subprocess.run([str(python), "-c", "import inscribe_build; "
                                 "print(inscribe_build.build_directory()[0])"],
                                capture_output=True, text=True, env=env, cwd="/").stdout.strip()
        assert folder == str(SOURCE_DIR.resolve() / "build" / f"python-{soabi.strip()}")
        tag = run(python, "-c", "import inscribe_build; print(inscribe_build.wheel_tag())",
                  PYTHONPATH=str(SOURCE_DIR / "python" / "build_backend")).strip()
        has_pip = subprocess.run([str(python), "-m", "pip", "--version"],
                                 capture_output=True).returncode == 0
        if has_pip:
            assert tag == preferred_linux_tag(python)


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
