"""`python3 -m impinge.view`: impinge view's server (see impinge.view.main)."""
import sys

from impinge.view import main

sys.exit(main())
