"""Tension-only cable-net solver: numpy + scipy, independent of printgen."""

from solver.laws import Law, linear, piecewise
from solver.loads import Drag, Hydrostatic, PointLoads
from solver.model import Net, SlidingCable
from solver.newton import solve, solve_path
from solver.result import Result, SolverError

__all__ = ["Drag", "Hydrostatic", "Law", "Net", "PointLoads", "Result", "SlidingCable",
           "SolverError", "linear", "piecewise", "solve", "solve_path"]
