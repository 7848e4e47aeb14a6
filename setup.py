"""The extension beamsim._beamsim for `pip install .` (pyproject.toml).

libbeamsim comes from CMake: the build in BEAMSIM_BUILD_DIR if it holds
libbeamsim.so, else a Release build of the library alone made here (the
dependencies scripts/deps.sh installs). The library is copied into the
package beside the extension, which finds it there ($ORIGIN), so the
installed package needs neither the source tree nor the build."""
import glob
import os
import shutil
import subprocess
import sys

import numpy
from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


class BuildWithLibrary(build_ext):
    def run(self):
        build = os.environ.get("BEAMSIM_BUILD_DIR")
        if not (build and os.path.exists(os.path.join(build, "libbeamsim.so"))):
            build = os.path.abspath(os.path.join(self.build_temp, "cmake"))
            jobs = str(os.cpu_count() or 1)
            subprocess.check_call(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                                   "-DBSIM_MPI=OFF"])
            subprocess.check_call(["cmake", "--build", build, "--target", "beamsim_shared",
                                   "-j", jobs])
        build = os.path.abspath(build)
        for ext in self.extensions:
            ext.include_dirs += [os.path.join(ROOT, "include"), os.path.join(build, "include"),
                                 numpy.get_include()]
            ext.library_dirs.append(build)
        super().run()
        # the library beside the extension, under the name it is linked by
        package = os.path.join(self.build_lib, "beamsim")
        lib = os.path.realpath(os.path.join(build, "libbeamsim.so"))
        soname = os.path.basename(glob.glob(os.path.join(build, "libbeamsim.so.[0-9]"))[0])
        shutil.copyfile(lib, os.path.join(package, soname))
        with open(os.path.join(package, "_built.py"), "w", encoding="utf-8") as f:
            f.write("# The Python the extension _beamsim was built for (written by setup.py).\n"
                    f"python = {sys.executable!r}\n"
                    f"version = \"{sys.version_info[0]}.{sys.version_info[1]}\"\n")


setup(
    ext_modules=[Extension(
        "beamsim._beamsim",
        sources=sorted(glob.glob(os.path.join("bindings", "python", "*.c"))),
        libraries=["beamsim"],
        extra_compile_args=["-std=c17"],
        extra_link_args=["-Wl,-rpath,$ORIGIN"],
    )],
    cmdclass={"build_ext": BuildWithLibrary},
)
