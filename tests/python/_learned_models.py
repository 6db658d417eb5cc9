"""A tiny learned model for the tests of what a model file records."""

from __future__ import annotations

import numpy as np

from roughwalk.learning import LearnedModel, ProblemSpec, build_problem
from roughwalk.learning.mlp import MLP
from roughwalk.learning.model_file import MODEL_FORMAT, problem_signature
from roughwalk.trajopt import HeuristicInitializer, Task
from roughwalk.trajopt.task import resolve

SPEC = ProblemSpec("anymal_c", "flat", "walk", 4, 2.0)
"""The problem the model is made for: ANYmal C, a 4-step walk on flat ground in 2 s."""


def heuristic_guess_model(**header: object) -> LearnedModel:
    """A model of ``SPEC`` whose every prediction is the heuristic's guess of one task.

    ``header`` adds fields to the model file's header (``constraints``,
    ``costs``, ...); a field set to None is left out, as in an older file.
    """
    problem = build_problem(SPEC)
    nlp = problem.formulation
    n_out = nlp.n_variables
    guess = HeuristicInitializer().guess(
        nlp, resolve(Task((0, 0, 0), (0.4, 0, 0)), problem.body, problem.terrain)
    )
    weights = (np.zeros((6, 5), np.float32), np.zeros((5, n_out), np.float32))
    biases = (np.zeros(5, np.float32), np.zeros(n_out, np.float32))
    mlp = MLP(weights, biases, "tanh", np.zeros(6), np.ones(6), guess, np.ones(n_out))
    fields: dict[str, object] = {
        "format": MODEL_FORMAT,
        "version": 1,
        "problem": SPEC.to_dict(),
        "layout": problem_signature(nlp)["layout"],
    }
    fields.update({k: v for k, v in header.items() if v is not None})
    return LearnedModel(mlp, fields)
