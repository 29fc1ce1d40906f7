"""pip install . : builds the `manisoft` Python package with CMake and installs it.

Offline, with Debian's pip, setuptools and wheel (no build isolation: nothing is downloaded):

    python3 -m venv --system-site-packages .venv      # Debian's numpy, h5py, torch stay visible
    .venv/bin/pip install --no-build-isolation .

CMake configures a Release build of the module in build/pip (or builds the target in an existing
build folder named by MANISOFT_CMAKE_BUILD_DIR, configured as it is) and the package it assembles
there (the compiled module, __init__ and the scripts that run as modules: python3 -m
manisoft.evaluate) becomes the installed package.
"""
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))
with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
    VERSION = re.search(r"project\(ManiSoft VERSION ([0-9.]+)", f.read()).group(1)  # the one version number


class CMakePackage(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("MANISOFT_CMAKE_BUILD_DIR")
        if not build:
            build = os.path.join(ROOT, "build", "pip")
            subprocess.run(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release", f"-DPython3_EXECUTABLE={sys.executable}",
                            "-DMANISOFT_BUILD_TESTS=OFF", "-DMANISOFT_BUILD_BENCHMARKS=OFF"], check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        subprocess.run(["cmake", "--build", build, "--target", "manisoft_python", "-j", jobs], check=True)
        package = os.path.join(build, "python", "manisoft")
        target = os.path.dirname(self.get_ext_fullpath(ext.name))
        os.makedirs(target, exist_ok=True)
        for name in os.listdir(package):
            if name.endswith((".py", ".so")):
                shutil.copy2(os.path.join(package, name), os.path.join(target, name))


setup(
    name="manisoft",
    version=VERSION,
    description="Soft continuum arm simulation and the ManiSoft manipulation benchmark (Gymnasium-style environments)",
    license="see the repository",
    python_requires=">=3.9",
    install_requires=["numpy"],
    ext_modules=[Extension("manisoft._manisoft", sources=[])],
    cmdclass={"build_ext": CMakePackage},
    zip_safe=False,
)
