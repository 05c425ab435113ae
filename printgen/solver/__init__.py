"""Tension-only cable-net solver: numpy + scipy, independent of printgen."""

from .driver import METHODS, solve, solve_path
from .laws import Law, linear, piecewise
from .loads import Drag, Hydrostatic, PointLoads
from .model import Net, SlidingCable
from .result import Result, SolverError

__all__ = ["METHODS", "Drag", "Hydrostatic", "Law", "Net", "PointLoads", "Result", "SlidingCable",
           "SolverError", "linear", "piecewise", "solve", "solve_path"]
