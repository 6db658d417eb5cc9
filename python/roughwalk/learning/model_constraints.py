"""Which constraint set a learned model's guess is solved with: the one it was trained on.

A model predicts the solution and the multipliers of one NLP, constraint set
included. The double-pallet model trained with ``force_between_nodes`` (the
forces stay unilateral between their nodes, so that a controller can track
the plan) starts IPOPT near a solution of that NLP; solved without it, the
plan pulls on the ground again, and a model trained without it needs
hundreds of iterations with it on. The experience run records the set
(``run.json``) and training copies it into the model's header
(``constraints``).

The rule: a configuration that keeps :func:`~roughwalk.trajopt.melon_config`'s
default set (nobody chose one) is solved with the model's recorded set; a set
chosen explicitly (any other, e.g. ``--constraints towr``) is kept. Models
whose header records no set leave the configuration as it is.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from roughwalk.trajopt.parameters import MELON_REACH_CONSTRAINTS

if TYPE_CHECKING:
    from roughwalk.learning.model_file import LearnedModel
    from roughwalk.learning.problem_spec import ProblemSpec

__all__ = ["recorded_constraints", "constraints_for_model", "spec_for_learned"]


def recorded_constraints(model: LearnedModel) -> tuple[str, ...] | None:
    """The constraint set ``model`` was trained on (None: its header does not say)."""
    names: Any = model.header.get("constraints")
    if not names:
        return None
    return tuple(str(n) for n in names)


def constraints_for_model(model: LearnedModel, requested: tuple[str, ...]) -> tuple[str, ...]:
    """The set to solve ``model``'s guess with, the configuration asking ``requested``."""
    recorded = recorded_constraints(model)
    if recorded is None or tuple(requested) != MELON_REACH_CONSTRAINTS:
        return tuple(requested)
    return recorded


def spec_for_learned(spec: ProblemSpec, init: str = "learned") -> ProblemSpec:
    """``spec`` with the constraint set and cost weights of ``init``'s model that fits it.

    ``init`` is "learned" (the shipped model), "learned:FILE" or
    "learned_fixed_durations[:FILE]". A spec that
    names its set keeps it, and the weights it names (see
    :mod:`.model_costs`); one without a fitting model is returned unchanged
    (the heuristic then solves the default NLP).
    """
    from dataclasses import replace

    from roughwalk.errors import ConfigError
    from roughwalk.learning.initializer import model_for_spec
    from roughwalk.learning.model_costs import cost_changes, costs_for_model

    try:
        model = model_for_spec(init, spec)
    except ConfigError:
        return spec
    config = spec.config()
    changes: dict[str, Any] = {}
    chosen = constraints_for_model(model, config.constraints)
    if spec.constraints is None and chosen != config.constraints:
        changes["constraints"] = chosen
    weights = costs_for_model(model, config.costs)
    if weights != config.costs:
        changes["costs"] = tuple(sorted(cost_changes(weights).items()))
    return replace(spec, **changes) if changes else spec
