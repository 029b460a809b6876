"""`python -m radar_cli` runs the command-line interface."""

from radar_cli.cli import main

main()
