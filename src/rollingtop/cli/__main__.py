"""``python -m rollingtop.cli``: the command-line interface."""

from rollingtop.cli import main

main()
