"""Experiments: closed-loop trials, studies over many trials, their reports, comparisons, pictures and commands.

``trial`` wires world, perception, mapping and navigation into one run;
``study`` runs many on a process pool or Ray; ``report`` and ``pictures`` turn
results into tables and figures; ``compare`` pairs two studies trial by trial;
``trial_command``, ``study_command`` and ``compare_command`` are the
``abstract-map`` subcommands. May import every package before it.
"""
