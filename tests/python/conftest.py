"""Fixtures of the Python suite: where the source, build and meshes are, the CLI, and real
inscribed servers started on free ports. ctest sets INSCRIBE_SOURCE_DIR and INSCRIBE_BUILD_DIR
and puts build/python first on PYTHONPATH (tests/CMakeLists.txt)."""

import os
import pathlib
import subprocess
import threading

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("INSCRIBE_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
BUILD_DIR = pathlib.Path(os.environ.get("INSCRIBE_BUILD_DIR", SOURCE_DIR / "build"))
DATA_DIR = SOURCE_DIR / "data"
CLI = BUILD_DIR / "client" / "inscribe"
INSCRIBED = BUILD_DIR / "server" / "inscribed"


def mesh_path(name: str) -> str:
    path = DATA_DIR / name
    if not path.exists():
        pytest.fail(f"{path} is missing: run scripts/fetch-meshes")
    return str(path)


def run_cli(*args, check=True) -> subprocess.CompletedProcess:
    result = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True)
    if check and result.returncode != 0:
        raise AssertionError(f"inscribe {' '.join(map(str, args))} exited {result.returncode}: "
                             f"{result.stderr}")
    return result


class Server:
    """inscribed as a child process on 127.0.0.1, port chosen by the kernel."""

    def __init__(self, *flags):
        self.process = subprocess.Popen([str(INSCRIBED), "--listen", "127.0.0.1:0", *flags],
                                        stderr=subprocess.PIPE, text=True)
        self.address = None
        self.log = []
        for line in self.process.stderr:
            self.log.append(line)
            if line.startswith("inscribed listening on "):
                self.address = line.split()[-1]
                break
        if self.address is None:
            raise RuntimeError("inscribed did not start: " + "".join(self.log))
        # Keep reading its log so that the pipe never fills.
        threading.Thread(target=lambda: self.log.extend(self.process.stderr), daemon=True).start()

    def stop(self):
        self.process.terminate()
        self.process.wait(timeout=30)


@pytest.fixture(scope="session")
def server():
    s = Server("--jobs", "2")
    yield s
    s.stop()
