"""Builds the Python package with CMake (pyproject.toml declares it; `pip install .` runs this).

The extension module, the command-line tool (data/bin/hybridcont, run by the `hybridcont` command) and the
package's data are what CMake lays out in <build>/python/hybridcont (target hybridcont_python_package,
CMakeLists.txt); this copies that folder into the wheel. The build folder is
setuptools' temporary one, or HYBRIDCONT_CMAKE_BUILD_DIR (an existing build tree: only what changed is
rebuilt). CMake builds for the interpreter running pip (Python_EXECUTABLE). HYBRIDCONT_PREBUILT_PACKAGE (a
package folder a build laid out) installs that folder as it is, without CMake: the tests' way of checking
the packaging against the build they test.
"""
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        return re.search(r"project\(hybridcont VERSION ([0-9.]+)", f.read()).group(1)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        prebuilt = os.environ.get("HYBRIDCONT_PREBUILT_PACKAGE")
        if prebuilt:
            self.copy_package(prebuilt)
            return
        build = os.environ.get("HYBRIDCONT_CMAKE_BUILD_DIR") or os.path.join(os.path.abspath(self.build_temp), "cmake")
        if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
            generator = ["-G", "Ninja"] if shutil.which("ninja") else []
            subprocess.run(["cmake", "-S", ROOT, "-B", build, *generator, "-DCMAKE_BUILD_TYPE=Release",
                            "-DBUILD_TESTING=OFF", "-DHYBRIDCONT_BUILD_BENCH=OFF",
                            "-DPython_EXECUTABLE=" + sys.executable], check=True)
        else:  # an existing build tree: for this interpreter (a reconfigure that changes nothing is quick)
            subprocess.run(["cmake", build, "-DPython_EXECUTABLE=" + sys.executable], check=True,
                           stdout=subprocess.DEVNULL)
        subprocess.run(["cmake", "--build", build, "--target", "hybridcont_python_package", "--parallel"], check=True)
        self.copy_package(os.path.join(build, "python", "hybridcont"))

    def copy_package(self, package):
        if not os.path.exists(os.path.join(package, "__init__.py")):
            raise RuntimeError("%s holds no built package (build the target hybridcont_python_package)" % package)
        target = os.path.join(os.path.abspath(self.build_lib), "hybridcont")
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(package, target, ignore=shutil.ignore_patterns("__pycache__"))


# setuptools' own build folder inside the source tree's build/ (the CMake build folder of the README), apart.
setup(version=version(), ext_modules=[CMakeExtension("hybridcont._hybridcont")], cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": os.path.join("build", "pip")}}, zip_safe=False)
