"""Real spherical harmonics (kautz2002): the basis to any order, projection of functions, images and lights,
and exact rotation of coefficient vectors.  Pure numpy.

Conventions, everywhere in the engine (GLSL included): an expansion of order N has bands l = 0 .. N-1 and
N^2 coefficients, coefficient (l, m) at index l^2 + l + m; the real basis carries the Condon-Shortley
phase, as Blender's own GLSL and Sloan's "Stupid SH tricks" do (Y_1,-1 = -sqrt(3 / 4 pi) y,
Y_1,0 = sqrt(3 / 4 pi) z, Y_1,1 = -sqrt(3 / 4 pi) x).
"""
