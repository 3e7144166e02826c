"""Calibration: fitting model parameters to measured creep curves, WILAC regression builder."""
