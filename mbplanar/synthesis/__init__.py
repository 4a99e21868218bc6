"""Synthesis: seed 001's guiding mechanism, function generation (Freudenstein), motion generation
(Burmester); every design comes back as an mbplanar model checked by mbplanar's own analysis."""
