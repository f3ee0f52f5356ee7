"""The `hybridcont` command of an installed package (a wheel): runs the tool the package carries,
hybridcont/data/bin/hybridcont, which reads the package's own data (models, figure script, report viewer,
the headers model files compile against: app/install_paths.h). `hybridcont sweep` and `hybridcont plot` run
this interpreter (HYBRIDCONT_PYTHON), so a virtual environment's packages are theirs too."""
import os
import sys


def main():
    tool = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "bin", "hybridcont")
    if not os.access(tool, os.X_OK):
        sys.exit("hybridcont: this installation of the package carries no command-line tool (%s); build it with "
                 "CMake (the README's commands)" % tool)
    env = dict(os.environ)
    env.setdefault("HYBRIDCONT_PYTHON", sys.executable)
    os.execve(tool, [tool] + sys.argv[1:], env)


if __name__ == "__main__":
    main()
