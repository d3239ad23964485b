"""The model's numerics (private to ``sim``: run it through ``sim.model.Model``).

* ``layout``: where everything sits in the parameter row, the constants array and the
  state, computed from the registry's order (plain Python, no numba);
* ``kernel``: the source of the compiled model — one integrator (RK4 / ETDRK4, located
  events, substeps), the runners (from rest, batch, segments, chained, stream) and the
  built-in effects' terms; never imported as itself (``compose`` reads its text);
* ``compose``: writes the kernel for a set of terms (the empty set is the baseline, or
  the built-in union plus any added effects' forces) into one hash-named module;
* ``runs``: the runs behind ``Model`` (rows, batches, segments, stream).
"""
