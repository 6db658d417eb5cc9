"""Learned initial guesses for the dynamic NLP (Melon et al. 2020, §IV, Algorithm 1).

Sample tasks from an environment's :class:`TaskSpace`, solve them with the
heuristic guess (:func:`generate`, on a local pool or a Ray cluster),
keep the good solutions (:func:`cost_threshold`), learn task → solution with
a small MLP (:func:`train_model`), and iterate (:func:`learned_init_rounds`).
Importing this wing registers the ``learned`` / ``learned:MODEL`` initialiser
and ``learned_fixed_durations[:MODEL]`` (a fixed-duration model's guess for
the optimised-duration NLP) with :mod:`roughwalk.trajopt`.
"""

from roughwalk.learning.dataset import Dataset
from roughwalk.learning.executors import Executor, LocalExecutor, RayExecutor, make_executor
from roughwalk.learning.experience import ExperienceRun, SolveJob, generate, solve_job
from roughwalk.learning.filtering import FilterResult, cost_threshold, filter_good
from roughwalk.learning.fixed_durations_initializer import FixedDurationsInitializer
from roughwalk.learning.initializer import LearnedInitializer, load_model, shipped_models
from roughwalk.learning.iterate import RoundReport, learned_init_rounds
from roughwalk.learning.model_file import LearnedModel
from roughwalk.learning.problem_spec import ProblemSpec, build_problem, variable_layout
from roughwalk.learning.task_cost_model import TaskCostModel
from roughwalk.learning.task_space import ENVIRONMENTS, TaskSpace, task_space
from roughwalk.learning.training import CATEGORY_WEIGHTS, TrainReport, train_model

__all__ = [
    "TaskSpace",
    "task_space",
    "ENVIRONMENTS",
    "ProblemSpec",
    "build_problem",
    "variable_layout",
    "Dataset",
    "Executor",
    "LocalExecutor",
    "RayExecutor",
    "make_executor",
    "ExperienceRun",
    "SolveJob",
    "generate",
    "solve_job",
    "FilterResult",
    "cost_threshold",
    "filter_good",
    "TaskCostModel",
    "CATEGORY_WEIGHTS",
    "TrainReport",
    "train_model",
    "LearnedModel",
    "LearnedInitializer",
    "FixedDurationsInitializer",
    "load_model",
    "shipped_models",
    "RoundReport",
    "learned_init_rounds",
]
