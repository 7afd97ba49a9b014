"""``python -m rollingtop``: the command-line interface."""

from rollingtop.cli import main

main()
