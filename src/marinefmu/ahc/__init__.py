"""Active heave compensation (issue 9): winch and load physics, controller, design."""
