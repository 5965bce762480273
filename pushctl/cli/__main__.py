"""``python -m pushctl.cli``: the ``pushctl`` command (as the console script)."""

from pushctl.cli import main

main()
