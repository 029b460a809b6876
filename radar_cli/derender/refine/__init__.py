"""Fitting one object to its photograph after the network: shape and pitch to the silhouette, then lighting."""
