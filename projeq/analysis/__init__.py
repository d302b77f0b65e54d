"""Analysis of a model: linearisation about equilibria and steady motions, eigenvalues."""
