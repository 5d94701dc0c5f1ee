"""Experiments: closed-loop trials, studies over many trials, their reports, pictures and commands.

``trial`` wires world, perception, mapping and navigation into one run;
``study`` runs many on a process pool or Ray; ``report`` and ``pictures`` turn
results into tables and figures; ``trial_command`` and ``study_command`` are
the ``abstract-map`` subcommands. May import every package before it.
"""
