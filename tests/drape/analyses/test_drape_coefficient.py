"""Drape coefficient, shadow union and node counting on synthetic shapes with known answers.

The meshes here are a private polar-grid annulus (nodes exactly on the disc and hem
circles), so the expected areas of the undeformed and synthetically deformed shapes can
be computed independently (polygon / quadrature formulas), not through shapely.
"""
import numpy as np
import pytest

from drape.analyses.drape_coefficient import (CusickError, boundary_radius, drape_analysis, drape_coefficient,
                          find_nodes, plot_top_view, shadow_polygon)

R, RD = 0.15, 0.09  # 30 cm specimen on an 18 cm disc


def polar_annulus(n_sectors=360, n_rings=4, r_in=RD, r_out=R):
    """Structured annulus: ``n_rings + 1`` circles of ``n_sectors`` nodes; returns rho, phi, tri."""
    rho = np.repeat(np.linspace(r_in, r_out, n_rings + 1), n_sectors)
    phi = np.tile(np.arange(n_sectors) * 2 * np.pi / n_sectors, n_rings + 1)
    tri = []
    for i in range(n_rings):
        for j in range(n_sectors):
            a, b = i * n_sectors + j, i * n_sectors + (j + 1) % n_sectors
            c, d = a + n_sectors, b + n_sectors
            tri += [[a, b, d], [a, d, c]]
    return rho, phi, np.array(tri)


def cart(rho, phi, z=None):
    z = np.zeros_like(rho) if z is None else z
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])


def hem_map(rho, phi, r_hem):
    """Map the annulus radially so that its hem follows ``r_hem(phi)``, hanging below the disc."""
    t = (rho - RD) / (R - RD)
    r = RD + t * (r_hem(phi) - RD)
    z = -t * np.sqrt(np.maximum((R - RD) ** 2 - (r_hem(phi) - RD) ** 2, 0.0))
    return cart(r, phi, z)


def polygon_area(n, radius):
    """Area of a regular n-gon inscribed in a circle of the given radius."""
    return 0.5 * n * radius**2 * np.sin(2 * np.pi / n)


@pytest.mark.parametrize("n_sectors", [24, 48, 96])  # > max_mode = 20 sectors
def test_undeformed_annulus_dc_is_one_up_to_polygon_error(n_sectors):
    rho, phi, tri = polar_annulus(n_sectors, 3)
    res = drape_analysis(cart(rho, phi), tri, R, RD)
    # the shadow is the regular hem polygon (the disc circle lies inside it)
    expected = (polygon_area(n_sectors, R) - np.pi * RD**2) / (np.pi * (R**2 - RD**2))
    assert res.drape_coefficient == pytest.approx(expected, rel=1e-9)
    # and that discretisation error is small: 1 - DC ~ (2 pi / n)^2 / 6 * R^2 / (R^2 - RD^2)
    assert 1 - res.drape_coefficient == pytest.approx(
        (2 * np.pi / n_sectors) ** 2 / 6 * R**2 / (R**2 - RD**2), rel=0.05)
    assert res.n_nodes == 0  # the hem polygon's corners are not folds


def test_triangle_soup_with_round_off_seams_reads_like_the_mesh():
    """A surface sampled element by element repeats every shared point with its own
    round-off (here 1e-15 relative). GEOS's overlay of such near-coincident seams once cut a
    2–3 cm notch into a flat hem (a spurious node); the shadow must equal the mesh's."""
    rho, phi, tri = polar_annulus(96, 3)
    pts = cart(rho, phi)
    soup = pts[tri].reshape(-1, pts.shape[1])
    soup = soup * (1 + 1e-15 * np.random.default_rng(0).standard_normal(soup.shape))
    res = drape_analysis(soup, np.arange(len(soup)).reshape(-1, 3), R, RD)
    ref = drape_analysis(pts, tri, R, RD)
    assert res.n_nodes == 0
    assert res.drape_coefficient == pytest.approx(ref.drape_coefficient, rel=1e-9)
    assert res.radius.min() == pytest.approx(ref.radius.min(), rel=1e-9)


def test_overlapping_folds_count_once():
    # phi -> 2 phi wraps the specimen twice around: every shadow point is covered twice
    n = 96
    rho, phi, tri = polar_annulus(n, 3)
    pts = cart(rho, 2 * phi)
    shadow = shadow_polygon(pts, tri, RD)
    p = pts[tri][:, :, :2]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    tri_sum = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]).sum()
    # round-off of the coincident images of nodes j and j + n/2 leaves ~1e-8 slivers
    assert shadow.area == pytest.approx(polygon_area(n // 2, R), rel=1e-6)
    assert tri_sum == pytest.approx(2 * (polygon_area(n // 2, R) - polygon_area(n // 2, RD)), rel=1e-9)


def lobed_hem(r0, amp, n):
    return lambda phi: r0 + amp * np.cos(n * phi)


def chord_area_bound(r_hem, phi_nodes, n, r0, amp):
    """Upper bound of |polygon area - curve area| for the hem r(phi): sum kappa_max l^3 / 12."""
    t = np.linspace(0, 2 * np.pi, 20001)
    r = r0 + amp * np.cos(n * t)
    r1 = -amp * n * np.sin(n * t)
    r2 = -amp * n**2 * np.cos(n * t)
    kappa = np.abs(r**2 + 2 * r1**2 - r * r2) / (r**2 + r1**2) ** 1.5
    xy = np.column_stack([r_hem(phi_nodes) * np.cos(phi_nodes), r_hem(phi_nodes) * np.sin(phi_nodes)])
    seg = np.linalg.norm(np.roll(xy, -1, axis=0) - xy, axis=1)
    return kappa.max() * np.sum(seg**3) / 12


@pytest.mark.parametrize("n", [3, 6, 10])
def test_lobed_hem_area_matches_quadrature(n):
    r0, amp, ns = 0.125, 0.02, 360
    rho, phi, tri = polar_annulus(ns, 4)
    r_hem = lobed_hem(r0, amp, n)
    res = drape_analysis(hem_map(rho, phi, r_hem), tri, R, RD)
    exact_area = np.pi * (r0**2 + amp**2 / 2)  # (1/2) int r(phi)^2 dphi
    tol = chord_area_bound(r_hem, phi[:ns], n, r0, amp) / (np.pi * (R**2 - RD**2))
    expected_dc = (exact_area - np.pi * RD**2) / (np.pi * (R**2 - RD**2))
    assert abs(res.drape_coefficient - expected_dc) <= tol
    assert tol < 5e-3  # the bound is tight enough to mean something


@pytest.mark.parametrize("n", range(3, 11))
def test_node_count_and_depth_noise_free(n):
    r0, amp = 0.125, 0.02
    rho, phi, tri = polar_annulus(360, 2)
    res = drape_analysis(hem_map(rho, phi, lobed_hem(r0, amp, n)), tri, R, RD)
    assert res.n_nodes == n
    # depth 2A; polygon chords and ray sampling cost < 2 % at 360 sectors
    np.testing.assert_allclose(res.node_depths, 2 * amp, rtol=0.02)
    crest = (np.arange(n) * 2 * np.pi / n)
    got = np.sort(res.node_angles)
    np.testing.assert_allclose(got, crest, atol=2 * np.pi / 360 + 1e-12)


@pytest.mark.parametrize("n", [3, 5, 8, 10])
def test_node_count_with_noise(n):
    r0, amp = 0.125, 0.02
    rng = np.random.default_rng(n)
    rho, phi, tri = polar_annulus(360, 2)
    noise = dict(zip(np.round(phi[:360], 12), 0.05 * amp * rng.standard_normal(360)))

    def r_hem(p):
        return r0 + amp * np.cos(n * p) + np.array([noise[v] for v in np.round(p, 12)])

    res = drape_analysis(hem_map(rho, phi, r_hem), tri, R, RD)
    assert res.n_nodes == n
    np.testing.assert_allclose(res.node_depths, 2 * amp, rtol=0.15)


def test_unequal_nodes_and_single_node():
    phi = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    # maxima at 0, pi (r - 0.12 = 0.03) and minor ones at pi/2, 3pi/2 (-0.01) between minima
    # at cos(2 phi) = -1/2 (-0.015): minor prominence 0.005 = 11 % of the 0.045 peak-to-peak
    r = 0.12 + 0.02 * np.cos(2 * phi) + 0.01 * np.cos(4 * phi)
    assert len(find_nodes(r, rel_prominence=0.15)[0]) == 2
    assert len(find_nodes(r, rel_prominence=0.10)[0]) == 4
    r = 0.12 + 0.02 * np.cos(phi - 1.0)
    peaks, depths = find_nodes(r)
    assert len(peaks) == 1 and phi[peaks[0]] == pytest.approx(1.0, abs=2 * np.pi / 720)
    assert depths[0] == pytest.approx(0.04, rel=1e-4)


def test_flat_outline_below_floor_has_no_nodes():
    phi = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    r = 0.15 + 1e-5 * np.cos(7 * phi)  # numerical ripple of 10 micrometres
    assert len(find_nodes(r, min_prominence=0.02 * (R - RD))[0]) == 0
    assert len(find_nodes(r)[0]) == 7  # without the floor the ripple would count


def test_mesh_scale_ripple_is_filtered_but_folds_are_not():
    phi = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    # outline of a 24-gon hem (corner prominence R (1 - cos(pi/24)) = 1.3 mm) with 3 shallow folds
    half = np.pi / 24
    polygon = R * np.cos(half) / np.cos(np.mod(phi, 2 * half) - half)
    r = polygon - 0.003 + 0.003 * np.cos(3 * phi)
    assert len(find_nodes(r)[0]) == 3
    assert len(find_nodes(r, max_mode=None)[0]) > 3


def test_boundary_radius_of_circle_and_offset_centre():
    rho, phi, tri = polar_annulus(720, 1)
    shadow = shadow_polygon(cart(rho, phi), tri, RD)
    ang, r = boundary_radius(shadow, n_samples=360)
    assert np.all(np.abs(r - R) <= R * (1 - np.cos(np.pi / 720)) + 1e-12)
    ang, r = boundary_radius(shadow, centre=(0.05, 0.0), n_samples=4)
    np.testing.assert_allclose(r, [0.10, np.sqrt(R**2 - 0.05**2), 0.20, np.sqrt(R**2 - 0.05**2)],
                               rtol=1e-4)


def test_drape_coefficient_of_disc_alone_and_errors():
    assert drape_coefficient(np.pi * RD**2, R, RD) == pytest.approx(0.0, abs=1e-15)
    with pytest.raises(CusickError, match="specimen_radius"):
        drape_coefficient(1.0, 0.05, 0.09)
    with pytest.raises(CusickError, match="points"):
        shadow_polygon(np.full((3, 2), np.nan), [[0, 1, 2]])
    with pytest.raises(CusickError, match="triangles"):
        shadow_polygon(np.zeros((3, 2)), [[0, 1]])


def test_top_view_png(tmp_path):
    rho, phi, tri = polar_annulus(180, 2)
    res = drape_analysis(hem_map(rho, phi, lobed_hem(0.12, 0.02, 5)), tri, R, RD)
    path = plot_top_view(res, tmp_path / "top.png", title="five lobes")
    assert path.stat().st_size > 10_000
    import matplotlib.image as mpimg
    img = mpimg.imread(path)
    assert img.ndim == 3 and img.shape[0] > 400


def test_cusick_post_on_a_cusick_mesh(tmp_path):
    """The runner hook: reference mesh + nodal displacement (either layout) -> summary + PNG."""
    import meshes
    from drape.analyses.drape_coefficient import cusick_post

    mesh = meshes.cusick_annulus(0.30, 0.18, n_radial=3, n_circumferential=96)
    x, y = mesh.p
    rho, phi = np.hypot(x, y), np.arctan2(y, x)
    target = hem_map(rho, phi, lobed_hem(0.125, 0.015, 4))
    disp = target - np.column_stack([x, y, np.zeros_like(x)])
    table = {"specimen_diameter": 0.30, "disc_diameter": 0.18}
    out = cusick_post(mesh, disp, table, tmp_path, name="four")
    out_t = cusick_post(mesh, disp.T, table)
    assert out["n_nodes"] == 4 and out_t["n_nodes"] == 4
    assert out["drape_coefficient"] == pytest.approx(out_t["drape_coefficient"], rel=1e-12)
    exact = (np.pi * (0.125**2 + 0.015**2 / 2) - np.pi * RD**2) / (np.pi * (R**2 - RD**2))
    assert out["drape_coefficient"] == pytest.approx(exact, abs=5e-3)  # 96-sector hem polygon
    assert (tmp_path / "four_top_view.png").exists()
    with pytest.raises(CusickError, match="disc_diameter"):
        cusick_post(mesh, disp, {"specimen_diameter": 0.30})
    with pytest.raises(CusickError, match="displacement"):
        cusick_post(mesh, disp[:-1], table)
