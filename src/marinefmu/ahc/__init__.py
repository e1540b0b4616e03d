"""Active heave compensation: the winch and load physics (:mod:`.winch`), the controller
(:mod:`.controller`), its design with python-control (:mod:`.design`) and the design loop that
identifies, tunes and verifies it on a co-simulated system (:mod:`.loop`)."""
