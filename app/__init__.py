"""alight: a physically based material editor and headless renderer."""

__version__ = "0.1.0"
