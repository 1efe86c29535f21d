from capnav.cli import main

main()
