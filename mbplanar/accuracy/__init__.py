"""The accuracy of mechanisms: toleranced dimensions and joint clearances, their effect on every point,
link angle and joint value over the cycle."""
