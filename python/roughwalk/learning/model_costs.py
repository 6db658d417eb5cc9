"""Which cost weights a learned model's guess is solved with: the ones it was trained on.

A model predicts the optimum of one NLP, its objective included: a model
trained on solves with ``costs.force_between_nodes_penalty=10`` starts IPOPT
near a point that the default objective (no penalty) moves away from. The
experience run records the weights that differ from
:func:`~roughwalk.trajopt.melon_config`'s (``run.json``, ``costs``, dotted
names such as ``force_between_nodes_penalty`` or ``force.weight``) and
training copies them into the model's header.

The rule, per recorded weight, as for the constraint set
(:mod:`.model_constraints`): a configuration that keeps the default value
of that weight (nobody chose one) is solved with the recorded value; a
value chosen explicitly (``costs__force__weight=0.1``, ``--set
costs.force.weight=0.1``, ``--trajopt``) is kept, so a user's override
always wins. A chosen value equal to the default cannot be told from no
choice: to solve such a model without its recorded weight, pass a
configuration built with the weight changed after this rule (or retrain).
Models whose header records no weights (every model made before the field
existed, and those trained on the default weights) leave the weights as
they are.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from roughwalk.config import override, to_dict
from roughwalk.trajopt.parameters import CostWeights, melon_config

if TYPE_CHECKING:
    from roughwalk.learning.model_file import LearnedModel

__all__ = ["cost_leaves", "cost_changes", "recorded_costs", "costs_for_model"]


def cost_leaves(costs: CostWeights) -> dict[str, Any]:
    """Every weight of ``costs`` by dotted name ("force.weight", "step_edge")."""
    out: dict[str, Any] = {}
    for key, value in to_dict(costs).items():
        if isinstance(value, dict):
            out.update({f"{key}.{k}": v for k, v in value.items()})
        else:
            out[key] = value
    return out


def cost_changes(costs: CostWeights) -> dict[str, float]:
    """The weights of ``costs`` that differ from the default configuration's, by dotted name."""
    default = cost_leaves(melon_config().costs)
    return {k: float(v) for k, v in cost_leaves(costs).items() if v != default.get(k)}


def recorded_costs(model: LearnedModel) -> dict[str, float] | None:
    """The non-default weights ``model`` was trained with (None: its header does not say)."""
    recorded: Any = model.header.get("costs")
    if not recorded:
        return None
    return {str(k): float(v) for k, v in recorded.items()}


def costs_for_model(model: LearnedModel, requested: CostWeights) -> CostWeights:
    """The weights to solve ``model``'s guess with, the configuration asking ``requested``."""
    recorded = recorded_costs(model)
    if recorded is None:
        return requested
    chosen = cost_changes(requested)
    apply = {k: v for k, v in recorded.items() if k not in chosen}
    return override(requested, apply) if apply else requested
