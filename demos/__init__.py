"""Runnable demo scenes: ``atmos demo NAME`` (see atmos.demo_registry)."""
