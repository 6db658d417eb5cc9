"""A tiny learned model for the tests of what a model file records, and the shipped
single-pallet model's problem for the tests of learned solves."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from roughwalk.learning import LearnedModel, ProblemSpec, build_problem, task_space
from roughwalk.learning.experience import generate
from roughwalk.learning.initializer import load_model
from roughwalk.learning.mlp import MLP
from roughwalk.learning.model_constraints import constraints_for_model
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


SHIPPED_PALLET_MODEL = "anymal_c_single_pallet_walk16"
"""The shipped single-pallet walk model (16 steps, 5.5 s)."""


def shipped_pallet_spec() -> ProblemSpec:
    """The problem :data:`SHIPPED_PALLET_MODEL` solves, with the model's constraint set."""
    model = load_model(SHIPPED_PALLET_MODEL)
    spec = ProblemSpec("anymal_c", "single_pallet", "walk", 16, 5.5)
    return replace(spec, constraints=constraints_for_model(model, spec.config().constraints))


def run_one_held_out_task(run_dir: Path, task: int) -> dict[str, Any]:
    """Held-out task ``task`` solved from the shipped model through an experience run.

    Held-out runs (bench init, LearnedInit re-solves) hand the model's guesses
    over precomputed; what a learned solve does after its first start must
    happen there too.
    """
    model = load_model(SHIPPED_PALLET_MODEL)
    return generate(
        shipped_pallet_spec(),
        task_space("single_pallet"),
        1,
        run_dir,
        split="test",
        max_iter=100,
        model=model,
        init=f"learned:{SHIPPED_PALLET_MODEL}",
        progress=None,
        indices=[task],
    )
