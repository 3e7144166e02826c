"""Readers and writers: parameter files (TOML) and measured creep curves (CSV)."""
