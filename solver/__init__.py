"""Tension-only cable-net solver: numpy + scipy, independent of printgen."""

from solver.driver import METHODS, solve, solve_path
from solver.laws import Law, linear, piecewise
from solver.loads import Drag, Hydrostatic, PointLoads
from solver.model import Net, SlidingCable
from solver.result import Result, SolverError

__all__ = ["METHODS", "Drag", "Hydrostatic", "Law", "Net", "PointLoads", "Result", "SlidingCable",
           "SolverError", "linear", "piecewise", "solve", "solve_path"]
