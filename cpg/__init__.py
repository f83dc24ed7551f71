"""Central pattern generators in NumPy: the 4-cell Morris–Lecar network of the source paper,
the 12-neuron Matsuoka network and a Hopf network, with phase analysis and the gait
classifier. Pure NumPy (+ numba for the hot kernel); never imports MuJoCo.
"""
from .errors import InputError, NotOscillatingError
from .gaits import GAITS, PRIMARY, SECONDARY, classify
from .morris_lecar import CELLS, PRESETS

__all__ = ["CELLS", "GAITS", "PRESETS", "PRIMARY", "SECONDARY", "InputError",
           "NotOscillatingError", "classify"]
