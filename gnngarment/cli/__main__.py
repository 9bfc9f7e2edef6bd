"""``python -m gnngarment.cli``."""

from gnngarment.cli import main

main()
