from percept.cli import main

main()
