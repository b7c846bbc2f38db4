"""Scenes and their symbols: place a scene in the simulator and encode it.

Goal symbols are the effect model's codes of the goal scene, rendered by placing the objects
at the goal poses; execution compares observed codes with them (and judges success by
symlearn.problems.problem.max_goal_distance).
"""
from __future__ import annotations

import numpy as np

from pddl_export.symbolic import SymbolicGoal
from symlearn.problems.problem import Problem
from symlearn.world import Scene


def place_scene(sim, scene: Scene) -> None:
    """Put the scene's objects at their poses (the arm at home) and let them settle."""
    sim.reset(scene)


def scene_codes(sim, encoder, scene: Scene) -> np.ndarray:
    """(k,) int64 codes of a scene: place it, render, encode with the effect model."""
    from symlearn.symbolic.transition_data import encode_observation

    place_scene(sim, scene)
    return encode_observation(encoder, sim.observe())


def goal_codes(sim, encoder, problem: Problem) -> np.ndarray:
    """The goal symbols of a problem: the encoder's codes of the goal scene's crops."""
    return scene_codes(sim, encoder, problem.goal)


def symbolic_goal(sim, encoder, problem: Problem) -> SymbolicGoal:
    """The problem's goal in codes: the goal scene's codes, None for the objects the goal leaves free."""
    codes = goal_codes(sim, encoder, problem)
    return SymbolicGoal(tuple(None if i in problem.free else int(c) for i, c in enumerate(codes)))
