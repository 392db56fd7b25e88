"""`python -m percept`: the console script (guarded: spawned worker processes import this module too)."""

if __name__ == "__main__":
    from percept.cli import main

    main()
