"""``python -m lagrange_gen.cli``: the lagrange-gen command."""

import sys

from .main import main

if __name__ == "__main__":
    sys.exit(main())
