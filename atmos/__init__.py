"""atmos: real-time atmospheric effects for Python games and demo scenes."""
