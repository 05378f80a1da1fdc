"""Generated point clouds with known boundaries, and checks on reconstructed meshes."""
import numpy as np
import pymeshlab


def fibonacci_sphere(n, jitter=0.0, rng=None):
    """n nearly uniform unit vectors (points on the unit sphere, also their outward normals);
    jitter: each moved by up to that many spacings in each direction (rng required)."""
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = np.pi * (3 - np.sqrt(5)) * i
    r = np.sqrt(1 - z * z)
    u = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
    if jitter:
        u += rng.uniform(-jitter, jitter, u.shape) * np.sqrt(4 * np.pi / n)
        u /= np.linalg.norm(u, axis=1, keepdims=True)
    return u


def cylinder(radius=1.0, height=2.0, spacing=0.04):
    """Open cylinder around z, z in [-height/2, height/2]: points, outward normals."""
    n_around = int(round(2 * np.pi * radius / spacing))
    n_up = int(round(height / spacing)) + 1
    theta, z = np.meshgrid(np.arange(n_around) * 2 * np.pi / n_around, np.linspace(-height / 2, height / 2, n_up))
    theta = theta + (np.arange(n_up)[:, None] % 2) * np.pi / n_around  # staggered rows
    normals = np.column_stack([np.cos(theta).ravel(), np.sin(theta).ravel(), np.zeros(theta.size)])
    return np.column_stack([radius * normals[:, :2], z.ravel()]), normals


def torus(R=1.0, r=0.4, spacing=0.035):
    """Torus around z: points, outward normals."""
    n_major = int(round(2 * np.pi * (R + r) / spacing))
    n_minor = int(round(2 * np.pi * r / spacing))
    u, v = np.meshgrid(np.arange(n_major) * 2 * np.pi / n_major, np.arange(n_minor) * 2 * np.pi / n_minor)
    u, v = u.ravel(), v.ravel()
    normals = np.column_stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)])
    centre = np.column_stack([R * np.cos(u), R * np.sin(u), np.zeros_like(u)])
    return centre + r * normals, normals


def sphere_circle(centre, angle, spacing):
    """Points on the unit sphere at geodesic distance `angle` from the unit vector `centre`,
    `spacing` apart (also their outward normals)."""
    centre = np.asarray(centre, dtype=float)
    u = np.cross(centre, [1.0, 0, 0] if abs(centre[0]) < 0.9 else [0, 1.0, 0])
    u /= np.linalg.norm(u)
    w = np.cross(centre, u)
    t = np.arange(max(3, int(np.ceil(2 * np.pi * np.sin(angle) / spacing)))) * 2 * np.pi
    t /= len(t)
    return np.cos(angle) * centre + np.sin(angle) * (np.cos(t)[:, None] * u + np.sin(t)[:, None] * w)


def torus_section(x0, R=1.0, r=0.4, spacing=0.035):
    """The torus of :func:`torus` cut by the plane x = x0 (|x0| < R - r): its two closed
    curves as points `spacing` apart along them, and the torus normals there."""
    v = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    rho = R + r * np.cos(v)
    points, normals = [], []
    for side in (1, -1):
        u = side * np.arccos(x0 / rho)
        curve = np.column_stack([rho * np.cos(u), rho * np.sin(u), r * np.sin(v)])
        arc = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(curve, axis=0), axis=1))])
        pick = np.unique(np.searchsorted(arc, np.arange(0, arc[-1], spacing)))
        points.append(curve[pick])
        normals.append(np.column_stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)])[pick])
    return np.concatenate(points), np.concatenate(normals)


def check_oriented_manifold(vertices, faces):
    """Asserts that the mesh is a 2-manifold with boundary, consistently oriented, finite."""
    assert np.all(np.isfinite(vertices))
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    assert len(np.unique(directed, axis=0)) == len(directed), "a directed edge twice: orientation flips"
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=faces))
    topology = ms.get_topological_measures()
    assert topology["non_two_manifold_edges"] == 0
    assert topology["non_two_manifold_vertices"] == 0


def moebius(half_width=0.3, spacing=0.02):
    """Möbius strip around a unit circle (one half twist): points and the parameters (u, w)
    of each, w being the signed distance across the strip (its boundary is |w| = half_width)."""
    u, w = np.meshgrid(np.arange(0, 2 * np.pi, spacing), np.arange(-half_width, half_width + 1e-9, spacing))
    u, w = u.ravel(), w.ravel()
    points = np.column_stack([(1 + w * np.cos(u / 2)) * np.cos(u), (1 + w * np.cos(u / 2)) * np.sin(u), w * np.sin(u / 2)])
    return points, u, w


def wavy_cap(n, seed=0):
    """n random (uniformly distributed) samples of the smooth open surface r = 1 + 0.03 sin 8x
    sin 8y over the unit directions with z > -0.2 (one boundary: the rim at the bottom), and
    its outward normals. Random samples, not a mesh's vertices: their gaps are what a scanner
    leaves."""
    rng = np.random.default_rng(seed)
    directions = np.empty((0, 3))
    while len(directions) < n:
        d = rng.normal(size=(2 * n, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        directions = np.vstack([directions, d[d[:, 2] > -0.2]])
    u = directions[:n]
    wave = 0.03 * np.sin(8 * u[:, 0]) * np.sin(8 * u[:, 1])
    # Gradient of |p| - (1 + wave(p / |p|)) at p = (1 + wave) u: the radial part minus the
    # wave's gradient projected onto the tangent plane, divided by the radius.
    grad = 0.24 * np.column_stack([np.cos(8 * u[:, 0]) * np.sin(8 * u[:, 1]),
                                   np.sin(8 * u[:, 0]) * np.cos(8 * u[:, 1]), np.zeros(n)])
    tangential = grad - np.sum(grad * u, axis=1, keepdims=True) * u
    normals = u - tangential / (1 + wave)[:, None]
    return u * (1 + wave)[:, None], normals / np.linalg.norm(normals, axis=1, keepdims=True)


def overlapping_caps(seed, shift_spacings=0.8, n=5000, edge_curl=0.0):
    """An open cap (the unit sphere above z = -0.5) scanned from four sides, in a new MeshSet:
    one layer per scan, a hemisphere of a jittered Fibonacci sphere of n points seen from its
    side, with exact normals, and a matrix that shifts it by shift_spacings of a scan's spacing
    in a random direction (the registration error the Align tool leaves). edge_curl: samples
    seen at grazing angles (the cosine of the view angle under 0.05: a scan's edge) are pulled
    up to that many spacings off the sphere, as mixed pixels pull a range scan's silhouette.
    Returns the MeshSet and the spacing within a scan."""
    rng = np.random.default_rng(seed)
    spacing = np.sqrt(4 * np.pi / n)
    ms = pymeshlab.MeshSet()
    for i, side in enumerate([[1, 0, 0.3], [-0.5, 0.87, 0.3], [-0.5, -0.87, 0.3], [0, 0, 1]]):
        u = fibonacci_sphere(n, jitter=0.3, rng=rng)
        u = u[(u[:, 2] > -0.5) & (u @ side > 0)]
        grazing = np.clip(1 - (u @ side) / np.linalg.norm(side) / 0.05, 0, 1)
        points = u * (1 + edge_curl * spacing * grazing)[:, None]
        shift = rng.normal(size=3)
        matrix = np.eye(4)
        matrix[:3, 3] = shift_spacings * spacing * shift / np.linalg.norm(shift)
        ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=u), f"scan {i}")
        ms.set_matrix(transformmatrix=matrix, freeze=False)
    return ms, spacing


def thin_plate(thickness_spacings=1.5, spacing=0.02, seed=0):
    """A closed plate (a flattened ellipsoid with semi-axes 1, 0.6 and half the thickness)
    whose two sides are `thickness_spacings` sample spacings apart: an ear or a fin. Samples
    about `spacing` apart on both sides (random, area-uniform), outward normals."""
    rng = np.random.default_rng(seed)
    c = 0.5 * thickness_spacings * spacing
    area = 2 * np.pi * 1 * 0.6  # both sides of the flat ellipse
    n = int(area / spacing ** 2)
    points = np.empty((0, 3))
    while len(points) < n:  # area-uniform on the flattened ellipsoid: by rejection on its projection
        xy = rng.uniform(-1, 1, (4 * n, 2)) * [1, 0.6]
        inside = (xy[:, 0] ** 2 + (xy[:, 1] / 0.6) ** 2) < 1
        xy = xy[inside]
        z = c * np.sqrt(np.maximum(0, 1 - xy[:, 0] ** 2 - (xy[:, 1] / 0.6) ** 2))
        side = rng.choice([-1, 1], len(xy))
        points = np.vstack([points, np.column_stack([xy, side * z])])
    points = points[:n]
    normals = points / np.array([1, 0.36, c * c])
    return points, normals / np.linalg.norm(normals, axis=1, keepdims=True)


def v_groove(opening_degrees=30, spacing=0.02, seed=0):
    """An open sheet folded into a V-groove of the given opening angle along the y axis (a
    sharp concave crease), flanks 1 long and 2 wide, jittered-grid samples `spacing` apart,
    normals pointing into the groove. One boundary: its rim."""
    rng = np.random.default_rng(seed)
    half = np.radians(opening_degrees) / 2
    u, y = np.meshgrid(np.arange(-1, 1, spacing) + spacing / 2, np.arange(-1, 1 + 1e-9, spacing))
    u = u.ravel() + rng.uniform(-0.3, 0.3, u.size) * spacing
    y = y.ravel() + rng.uniform(-0.3, 0.3, y.size) * spacing
    side = np.sign(u)
    points = np.column_stack([np.abs(u) * np.sin(half) * side, y, np.abs(u) * np.cos(half)])
    normals = np.column_stack([-side * np.cos(half), np.zeros_like(u), np.full_like(u, np.sin(half))])
    return points, normals


def uneven_hemisphere(ratio=10, smooth=False, n_dense=40000, seed=0):
    """The upper unit hemisphere (one boundary, its rim at z = 0), sampled `ratio` times more
    sparsely (in spacing) on the x < 0 half than on the x > 0 half. Abruptly at x = 0, as a
    scan's range grid changes at a fold: each half a jittered Fibonacci spiral; or smoothly
    over x in [-0.5, 0.5], as an adaptive decimation does: random samples, thinned. Outward
    normals."""
    rng = np.random.default_rng(seed)
    if smooth:
        d = rng.normal(size=(4 * n_dense, 3))
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        d = d[d[:, 2] > 0][:2 * n_dense]
        t = np.clip(d[:, 0] + 0.5, 0, 1)
        d = d[rng.random(len(d)) < ratio ** (-2 * (1 - t))]  # density falls by ratio squared
        return d, d.copy()
    halves = []
    for n, side in ((4 * n_dense, 1), (4 * n_dense // ratio ** 2, -1)):  # points on the whole sphere
        d = fibonacci_sphere(n, jitter=0.3, rng=rng)
        halves.append(d[(d[:, 2] > 0) & (side * d[:, 0] > 0)])
    d = np.vstack(halves)
    return d, d.copy()


def terrain_with_pond(spacing=0.01, noise=0.002, seed=0):
    """A terrain z = 0.1 sin(3x) cos(2y) over the unit square with a round pond (a hole of
    radius 0.15 at (0.6, 0.4)): two boundaries. Jittered-grid samples `spacing` apart, Gaussian
    noise of `noise` times the bounding-box diagonal on the points, exact normals."""
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.arange(0, 1 + 1e-9, spacing), np.arange(0, 1 + 1e-9, spacing))
    x = np.clip(x.ravel() + rng.uniform(-0.3, 0.3, x.size) * spacing, 0, 1)
    y = np.clip(y.ravel() + rng.uniform(-0.3, 0.3, y.size) * spacing, 0, 1)
    dry = np.hypot(x - 0.6, y - 0.4) > 0.15
    x, y = x[dry], y[dry]
    z = 0.1 * np.sin(3 * x) * np.cos(2 * y)
    normals = np.column_stack([-0.3 * np.cos(3 * x) * np.cos(2 * y), 0.2 * np.sin(3 * x) * np.sin(2 * y), np.ones_like(x)])
    points = np.column_stack([x, y, z])
    points += rng.normal(0, noise * np.linalg.norm(np.ptp(points, axis=0)), points.shape)
    return points, normals / np.linalg.norm(normals, axis=1, keepdims=True)
