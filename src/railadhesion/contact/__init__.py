"""Contact mechanics: Hertz, Kalker linear theory, FASTSIM."""
