"""The typer application behind the `percept` console script."""

from .app import app, main

__all__ = ["app", "main"]
