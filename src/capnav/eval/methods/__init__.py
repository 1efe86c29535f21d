"""Map-based methods: CapNav and its ablations (registered in ``capnav.eval.method.METHODS``)."""
