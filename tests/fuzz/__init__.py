"""navlab's input fuzzer: seeded malformed variants of every input format, run against the public loaders.

``seeds`` builds a valid example of each format from the shipped files, ``mutate`` derives malformed
variants (each marked invalid-by-construction or not), ``targets`` runs one case in a worker process
and ``runner`` classifies every case: ``clean`` (a NavlabError of at most 3 lines naming the file),
``vague`` (a NavlabError that is longer or names no place), ``accepted`` (loaded, and the mutation did
not make it invalid), ``accepted-invalid``, ``traceback`` (any other exception), ``hang`` (over the
per-case time limit), ``crash`` (the worker died: memory limit, signal) and ``escape`` (a robot
description ran code). ``python -m tests.fuzz --cases 2000`` runs the campaign and prints the table.
"""
