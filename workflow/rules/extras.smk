# Beyond-the-paper products (integrity, erosion profiles, true basins, Fourier comparison).
EXTRA_TARGETS = []


rule extras:
    input:
        EXTRA_TARGETS,
