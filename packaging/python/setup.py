"""Stages the CMake build's Python package into the wheel (pyproject.toml says what it is).

The package comes from `cmake --install BUILD --component python` and `--component
python_bundle` (the module with its $ORIGIN run path, and libhorus.so.0 beside it), BUILD being
HORUS_BUILD_DIR (default: build/default of this checkout); the version is the build's."""
import os
import pathlib
import re
import shutil
import subprocess
import tempfile

from setuptools import setup
from setuptools.dist import Distribution

HERE = pathlib.Path(__file__).resolve().parent
BUILD = pathlib.Path(os.environ.get("HORUS_BUILD_DIR", HERE.parent.parent / "build" / "default")).resolve()


def build_version():
    cache = (BUILD / "CMakeCache.txt").read_text()
    m = re.search(r"^CMAKE_PROJECT_VERSION:STATIC=(\S+)$", cache, re.M)
    if not m:
        raise SystemExit(f"setup.py: {BUILD}/CMakeCache.txt names no CMAKE_PROJECT_VERSION")
    return m.group(1)


class BinaryDistribution(Distribution):
    """A wheel for this platform and interpreter: it holds compiled code."""

    def has_ext_modules(self):
        return True


def stage():
    """The installed package, copied into stage/horus (relative to this file: setuptools wants
    package directories inside the project)."""
    if not (BUILD / "CMakeCache.txt").exists():
        raise SystemExit(f"setup.py: no CMake build in {BUILD} (set HORUS_BUILD_DIR, or run scripts/test.sh first)")
    target = HERE / "stage" / "horus"
    shutil.rmtree(HERE / "build", ignore_errors=True)  # setuptools' copy of an earlier stage
    with tempfile.TemporaryDirectory() as prefix:
        for component in ("python", "python_bundle"):
            subprocess.run(["cmake", "--install", str(BUILD), "--prefix", prefix, "--component", component],
                           check=True, stdout=subprocess.DEVNULL)
        modules = list(pathlib.Path(prefix).rglob("horus/_horus*.so"))
        if len(modules) != 1:
            raise SystemExit(f"setup.py: the build installed {len(modules)} modules horus/_horus*.so")
        package = modules[0].parent
        if not any(package.glob("libhorus.so.*")):
            raise SystemExit("setup.py: no libhorus.so.* beside the module (a build with HORUS_SHARED=OFF?)")
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(package, target, symlinks=True, ignore=shutil.ignore_patterns("__pycache__"))
    # A wheel holds no symbolic links: the library under its SONAME only (what the module needs),
    # and without its debug sections.
    for link in [f for f in target.iterdir() if f.is_symlink()]:
        real = link.resolve()
        link.unlink()
        shutil.move(real, link)
    for f in target.rglob("*.so*"):  # the module, the library and the transports' plug-ins (horus0/)
        subprocess.run(["strip", "--strip-debug", str(f)], check=True)


stage()
setup(version=build_version(), distclass=BinaryDistribution, package_dir={"horus": "stage/horus"})
