namespace smx::sim {}
