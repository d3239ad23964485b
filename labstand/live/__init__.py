"""The live view in Foxglove: a WebSocket server (foxglove-sdk) fed from a run or a file.

* ``address`` — ``--foxglove [HOST:]PORT``, loopback unless a host is given;
* ``server`` — the server and its topics (``/gauges`` at full rate, ``/model``, ...);
* ``model`` — the baseline model fed the measured drive position, block by block;
* ``feed`` — the bounded queue and the thread between the acquisition and the server;
* ``view`` — the hooks into ``labstand run`` (its recording pipe and display);
* ``player`` — a recording played to the server on an injected clock (``labstand play``).

Nothing here may slow or endanger the acquisition: the acquisition only ever calls
``put_nowait`` on a bounded queue; what does not fit is dropped and counted.
"""
