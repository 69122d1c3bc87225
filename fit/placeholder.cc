// Placeholder until the fit module lands.
