"""Benchmark suites: `paper` reproduces the seed paper's Table II."""
