"""Dobashi's cloud cellular automaton on the GPU (thesis sec. 2.3 and ch. 4).

``CloudAutomaton`` runs the automaton in compute shaders (layouts "packed" and "cell");
``reference`` holds the numpy reference that reproduces it bit for bit.
"""
from atmos.plugins.clouds.automaton.automaton import LAYOUTS, PRECISION_BITS, CloudAutomaton
from atmos.plugins.clouds.automaton import reference

__all__ = ["CloudAutomaton", "LAYOUTS", "PRECISION_BITS", "reference"]
