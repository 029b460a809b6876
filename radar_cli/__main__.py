"""`python -m radar_cli` runs the command-line interface."""

from radar_cli.cli import main

if __name__ == "__main__":  # not when a worker process started by spawn imports this module
    main()
