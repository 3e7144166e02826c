"""``python -m railadhesion``: the command-line interface."""

from railadhesion.cli import app

if __name__ == "__main__":
    app(prog_name="railadhesion")
