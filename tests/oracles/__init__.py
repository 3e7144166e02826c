"""Independent oracles of the compiled laws: readable NumPy implementations that the tests
hold the package's compiled code to (1e-12 relative). They are written from the published
equations, not from the package's code, and are never imported by the package."""
