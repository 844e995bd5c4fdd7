"""Effect plugins shipped with atmos, importable as ``atmos.plugins.<name>``."""
