"""Solver backends: each module is the only importer of its solver library (see docs/architecture.md)."""
