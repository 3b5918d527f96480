"""Triangle meshes for the benchmark scripts that write glTF files."""
import math


def uv_sphere(center, radius, rings, segments):
    """Positions, unit normals and triangle indices of a UV sphere (flat lists)."""
    positions, normals, indices = [], [], []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2.0 * math.pi * j / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            positions += [c + radius * d for c, d in zip(center, n)]
            normals += n
    for i in range(rings):
        for j in range(segments):
            a = i * (segments + 1) + j
            b = a + segments + 1
            indices += [a, b, a + 1, a + 1, b, b + 1]
    return positions, normals, indices
