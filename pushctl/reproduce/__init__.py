"""``make reproduce-tables`` (``pushctl reproduce``): the plan of its steps, each the
``pushctl`` command a user would type, run as a subprocess (:mod:`.plan`); running them in
order, timed (:mod:`.steps`); the manifest of how ``results/`` was made (:mod:`.manifest`).
The command line's ``reproduce`` parses its options and calls :func:`.steps.reproduce`."""
