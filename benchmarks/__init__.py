"""Benchmarks: the core against the libraries users would pick instead, and the HTTP service under load.

``python -m benchmarks.core`` and ``python -m benchmarks.http_throughput``; see benchmarks/README.md.
"""
