"""Running the network over a collection: reading and cropping inputs, predicting, batches, shares, timing."""
