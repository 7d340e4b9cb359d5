# PlatformIO Core runs `<python> <tool-scons>/scons.py ...`; this starts SCons 4.11.1 as
# installed from PyPI into the project's venv (python/pyproject.toml: scons==4.11.1). PlatformIO
# runs it with the interpreter it runs under, the venv's, so SCons imports from there.
import sys

from SCons.Script.Main import main  # type: ignore

if __name__ == "__main__":
    sys.exit(main())
