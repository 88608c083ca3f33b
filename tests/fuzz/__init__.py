"""The command-line fuzz (issue 43): generated cases over every command and option, checked by invariants.

- :mod:`.workspace`: the user's files every case runs among, and their snapshot (hashes) before and after;
- :mod:`.cases`: the deterministic generator of named cases;
- :mod:`.known`: the cases of bugs known and being fixed elsewhere (marked xfail, by name);
- :mod:`.runner`: one case run in this process or as a process of its own;
- :mod:`.invariants`: what every run must satisfy.
"""
