"""The MotionReferenceUnit's goals: max(2 cm, 5 % / 5 % / 2.5 % of std), the heave
goal raised to 1.2 × the causal bound where that is higher (issue's definition)."""
import numpy as np

from marinefmu.estimators.mru.goals import BOUND_FACTOR, goals


def test_the_heave_goal_follows_the_causal_bound_where_it_is_higher():
    std = np.array([[100.0, 20.0, 60.0], [100.0, 20.0, 200.0]])
    bound = np.array([[1.0, 1.0, 3.0], [1.0, 1.0, 3.0]])
    np.testing.assert_allclose(goals(std), [[5.0, 2.0, 2.0], [5.0, 2.0, 5.0]])
    # the bound moves heave only, and only where 1.2 × it is above the std's goal
    np.testing.assert_allclose(goals(std, bound), [[5.0, 2.0, BOUND_FACTOR * 3.0], [5.0, 2.0, 5.0]])
