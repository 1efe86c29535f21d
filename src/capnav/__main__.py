"""``python -m capnav``: the same command line as the ``capnav`` entry point."""

from capnav.cli import main

main()
