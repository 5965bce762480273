"""``python -m pushctl.bench``: :func:`pushctl.bench.suite.main`."""

import sys

from pushctl.bench.suite import main

sys.exit(main())
