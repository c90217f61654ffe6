"""tumble's version, imported by the package and by the writers that stamp it into files (below the package, so
that they need not import it)."""

__version__ = "0.1.0"
