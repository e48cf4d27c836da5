"""mccool2001's homomorphic factorization: the factored technique (factored) and its numpy mirror
(factored_shading); shaders/techniques/factored/."""
