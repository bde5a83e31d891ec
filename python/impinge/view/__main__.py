"""`python3 -m impinge.view`: impinge view's server (see impinge.view.main)."""
import sys

try:
    from impinge.view import main
except ImportError as e:  # an interpreter without the packages the server needs
    print(f"impinge: error: impinge view's Python ({sys.executable}) cannot import {e.name or e}: install Debian's "
          "python3-numpy and python3-aiohttp (tools/install-deps), or set IMPINGE_PYTHON to an interpreter with them",
          file=sys.stderr)
    sys.exit(2)

sys.exit(main())
