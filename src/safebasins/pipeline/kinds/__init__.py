"""The package's experiment kinds (each module registers its kinds on import)."""
