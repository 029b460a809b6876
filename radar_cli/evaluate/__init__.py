"""`radar eval`: the paper's metrics (Table 2) of de-rendering results against synthetic ground truth."""
