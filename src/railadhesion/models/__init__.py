"""Creep-force models: Polach, WILAC, 2D twin-disc models."""
