"""The model's numerics (private to ``sim``: run it through ``sim.model.Model``).

* ``layout``: where everything sits in the parameter row, the constants array and the
  state, computed from the registry's order (plain Python, no numba);
* ``kernel`` (the head: layout constants, state helpers, the terms' hook calls),
  ``fibre`` (forces and right-hand side), ``integrator`` (RK4 / ETDRK4 steps split at
  located events, substeps) and ``runners`` (from rest, batch, segments, chained,
  stream): the compiled model's text, never imported as itself; each physical effect's
  terms are in ``sim/effects/NAME/terms.py``;
* ``kernel_source`` and ``compose``: that text written for a set of terms (the empty set
  is the baseline; else the built-in union plus any added effects: their forces, their
  terms from their one file) into one hash-named module; ``added``: what ``register``
  checks before it adds an effect;
* ``runs`` and ``starts``: the runs behind ``Model`` (rows, batches, segments, stream)
  and the segments' start states from measurements.
"""
