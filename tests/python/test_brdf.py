"""igi.brdf: the reflectance models on arrays against the contract's formulas (written here
independently from docs and spec), reciprocity, energy, sampling and bad materials."""

import numpy as np
import pytest

import igi
from igi import brdf

RNG_SEED = 20240611


def hemisphere(rng, n, max_theta_deg=89.0):
    """n unit vectors above the surface (z > 0), uniform in (cos θ, φ) up to max_theta_deg."""
    cos_t = rng.uniform(np.cos(np.radians(max_theta_deg)), 1.0, n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    sin_t = np.sqrt(1.0 - cos_t**2)
    return np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t], axis=1)


def lobe_material(model, rho_d, rho_s, alpha):
    """A complete material of `model`: an anisotropic lobe gets αx = α, αy = α/2."""
    m = {"brdf": model, "rho_d": rho_d}
    if model == "lambert":
        return m
    m["rho_s"] = rho_s
    if "aniso" in model:
        m.update(alpha_x=alpha, alpha_y=0.5 * alpha)
    else:
        m["alpha"] = alpha
    return m


def material(model, **extra):
    """A complete material of `model` with plausible values (ρd + ρs <= 1)."""
    m = lobe_material(model, [0.5, 0.4, 0.3], [0.3, 0.4, 0.5], 0.15)
    m.update(extra)
    return m


# ---- the contract's formulas (spec/CONTRACT.md §2), in angles -------------------------------

def contract_ward(m, wi, wo):
    """The contract's f(l, v) of ward, ward_gmd, ward_aniso and ward_gmd_aniso, per channel."""
    rho_d = np.asarray(m["rho_d"], float)
    rho_s = np.asarray(m["rho_s"], float)
    h = wi + wo  # unnormalised
    cos_h = h[:, 2] / np.linalg.norm(h, axis=1)
    theta_h = np.arccos(np.clip(cos_h, -1, 1))
    tan2 = np.tan(theta_h) ** 2
    phi_h = np.arctan2(h[:, 1], h[:, 0])
    ax = m.get("alpha_x", m.get("alpha"))
    ay = m.get("alpha_y", m.get("alpha"))
    if m["brdf"] == "ward":
        lobe = np.exp(-tan2 / ax**2) / (4 * np.pi * ax**2 * np.sqrt(wi[:, 2] * wo[:, 2]))
    elif m["brdf"] == "ward_gmd":
        hh = np.sum(h * h, axis=1)
        lobe = hh / (np.pi * ax**2 * h[:, 2] ** 4) * np.exp(-tan2 / ax**2)
    elif m["brdf"] == "ward_aniso":
        e = tan2 * (np.cos(phi_h) ** 2 / ax**2 + np.sin(phi_h) ** 2 / ay**2)
        lobe = np.exp(-e) / (4 * np.pi * ax * ay * np.sqrt(wi[:, 2] * wo[:, 2]))
    else:  # ward_gmd_aniso: t = x, b = n × t = y in the local frame
        hh = np.sum(h * h, axis=1)
        e = ((h[:, 0] / ax) ** 2 + (h[:, 1] / ay) ** 2) / h[:, 2] ** 2
        lobe = hh / (np.pi * ax * ay * h[:, 2] ** 4) * np.exp(-e)
    return rho_d / np.pi + rho_s * lobe[:, None]


def test_models_cover_the_contract_and_the_additions():
    for name in ("lambert", "ward", "ward_gmd", "ward_aniso", "ward_gmd_aniso", "ggx",
                 "beckmann", "ggx_aniso", "beckmann_aniso", "ward_fresnel"):
        assert name in brdf.MODELS
    assert "emitter" not in brdf.MODELS and "black" not in brdf.MODELS


def test_lambert_is_rho_d_over_pi_exactly():
    rng = np.random.default_rng(RNG_SEED)
    wi, wo = hemisphere(rng, 1000), hemisphere(rng, 1000)
    f = brdf.evaluate({"brdf": "lambert", "rho_d": [0.8, 0.5, 0.25]}, wi, wo)
    assert f.shape == (1000, 3) and f.dtype == np.float64
    # Exact: ρd times the double nearest 1/π, as the renderer multiplies.
    np.testing.assert_array_equal(f, np.broadcast_to(np.array([0.8, 0.5, 0.25]) * (1 / np.pi),
                                                     (1000, 3)))
    # One-sided: zero below the surface.
    below = wi * np.array([1, 1, -1])
    assert not brdf.evaluate({"brdf": "lambert", "rho_d": 0.8}, below, wo).any()


@pytest.mark.parametrize("model", ["ward", "ward_gmd", "ward_aniso", "ward_gmd_aniso"])
def test_ward_models_match_the_contract(model):
    rng = np.random.default_rng(RNG_SEED)
    wi, wo = hemisphere(rng, 2000, 85), hemisphere(rng, 2000, 85)
    m = material(model)
    f = brdf.evaluate(m, wi, wo)
    # 1e-6 relative: the two evaluations differ by the rounding of tan²θh from angles (arccos
    # near θh = 0 loses about 8 digits of θh), far above double rounding, far below a wrong term.
    np.testing.assert_allclose(f, contract_ward(m, wi, wo), rtol=1e-6, atol=0)


def test_single_vectors_give_one_value():
    m = material("ggx")
    wi, wo = np.array([0.3, 0.1, 0.9]), np.array([-0.2, 0.4, 0.8])
    wi, wo = wi / np.linalg.norm(wi), wo / np.linalg.norm(wo)
    one = brdf.evaluate(m, wi, wo)
    assert one.shape == (3,)
    np.testing.assert_array_equal(one, brdf.evaluate(m, wi[None], wo[None])[0])
    # A (3,) vector stands for every row.
    many = brdf.evaluate(m, np.tile(wi, (4, 1)), wo)
    np.testing.assert_array_equal(many, np.tile(one, (4, 1)))


def every_material():
    """Every model, each diffuse term on one of them."""
    out = [material(name, ior=1.4) if "fresnel" in name else material(name)
           for name in brdf.MODELS]
    out.append(material("ward_gmd", diffuse="oren_nayar", sigma=0.4))
    out.append(material("ggx", diffuse="coated"))
    out.append(material("lambert", diffuse="oren_nayar", sigma=0.2))
    return out


@pytest.mark.parametrize("m", every_material(), ids=lambda m: m["brdf"] + "/" +
                         m.get("diffuse", "lambert"))
def test_every_model_is_reciprocal(m):
    rng = np.random.default_rng(RNG_SEED)
    wi, wo = hemisphere(rng, 3000), hemisphere(rng, 3000)
    forward = brdf.evaluate(m, wi, wo)
    assert np.all(np.isfinite(forward)) and forward.max() > 0
    # 1e-12 relative: the models are symmetric in form; only the order of operations differs.
    np.testing.assert_allclose(brdf.evaluate(m, wo, wi), forward, rtol=1e-12, atol=0)


def test_world_frame_equals_local_frame():
    """World directions with a normal and tangent give the local frame's values."""
    rng = np.random.default_rng(RNG_SEED)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    world_from_local = q * np.sign(np.linalg.det(q))  # a rotation
    wi, wo = hemisphere(rng, 500), hemisphere(rng, 500)
    m = material("beckmann_aniso")
    local = brdf.evaluate(m, wi, wo)
    normal, tangent = world_from_local[:, 2], world_from_local[:, 0]
    world = brdf.evaluate(m, wi @ world_from_local.T, wo @ world_from_local.T, normal=normal,
                          tangent=tangent)
    np.testing.assert_allclose(world, local, rtol=1e-9)
    # The material's own tangent serves when none is given.
    m_world = dict(m, tangent=tangent.tolist())
    np.testing.assert_allclose(
        brdf.evaluate(m_world, wi @ world_from_local.T, wo @ world_from_local.T, normal=normal),
        local, rtol=1e-9)


# The energy a model reflects, ∫ f·cosθi dωi, estimated by Monte Carlo with cosine-weighted
# directions (mean of π·f) from a seeded numpy generator. For ρd + ρs <= 1 it is at most 1 for
# every model with an energy-bounded lobe (Ward 1992 and GMD, GGX, Beckmann; Lambert's and the
# coated diffuse term). Left out: the *_fresnel models (ρs is their normal-incidence value and the
# lobe rises to ρs/F0 toward grazing, so ρd + ρs does not bound their albedo) and Oren–Nayar's
# qualitative model (1.013 at grazing views; docs/scene-format.md).
FURNACE_MODELS = ["lambert", "ward", "ward_gmd", "ward_aniso", "ward_gmd_aniso", "ggx",
                  "ggx_aniso", "beckmann", "beckmann_aniso"]


@pytest.mark.parametrize("model", FURNACE_MODELS)
def test_white_furnace(model):
    rng = np.random.default_rng(RNG_SEED)
    n = 400_000
    for theta_o in (0.0, 45.0, 75.0):
        for alpha in (0.1, 0.4):
            m = lobe_material(model, 0.3, 0.7, alpha)
            t = np.radians(theta_o)
            wo = np.array([np.sin(t), 0.0, np.cos(t)])
            r, phi = np.sqrt(rng.random(n)), 2 * np.pi * rng.random(n)
            wi = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - r * r)], axis=1)
            x = np.pi * brdf.evaluate(m, wi, wo)[:, 0]
            estimate, error = x.mean(), x.std() / np.sqrt(n)
            # 5 standard errors: a false failure has odds below 1e-6 per case.
            assert estimate <= 1.0 + 5 * error, (model, theta_o, alpha, estimate, error)
            assert estimate >= 0.3 - 5 * error  # at least the diffuse part


def test_sampling_agrees_with_evaluate_and_pdf():
    rng = np.random.default_rng(RNG_SEED)
    for m in every_material():
        wo = hemisphere(rng, 2000, 80)
        s = brdf.sample(m, wo, rng.random((2000, 3)))
        ok = s["valid"]
        assert ok.mean() > 0.5 and set(np.unique(s["lobe"][ok])) <= {1, 2}
        np.testing.assert_allclose(s["f"][ok], brdf.evaluate(m, s["wi"][ok], wo[ok]), rtol=1e-12)
        np.testing.assert_allclose(s["pdf"][ok], brdf.pdf(m, s["wi"][ok], wo[ok]), rtol=1e-9)
        weight = s["f"][ok] * s["wi"][ok, 2:3] / s["pdf"][ok, None]
        np.testing.assert_allclose(s["weight"][ok], weight, rtol=1e-9)
        assert not s["weight"][~ok].any()


def test_albedo_of_lambert_is_rho_d():
    # Cosine-weighted draws give weight ρd exactly, so the mean is ρd to rounding.
    a = brdf.albedo({"brdf": "lambert", "rho_d": [0.7, 0.5, 0.2]}, [0.0, 0.6, 0.8], samples=256)
    np.testing.assert_allclose(a, [0.7, 0.5, 0.2], rtol=1e-14)


def test_albedo_agrees_with_the_furnace_estimate():
    m = lobe_material("ggx", 0.0, 1.0, 0.3)
    wo = np.array([np.sin(0.6), 0.0, np.cos(0.6)])
    rng = np.random.default_rng(RNG_SEED)
    n = 400_000
    r, phi = np.sqrt(rng.random(n)), 2 * np.pi * rng.random(n)
    wi = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - r * r)], axis=1)
    x = np.pi * brdf.evaluate(m, wi, wo)[:, 0]
    samples = 100_000
    a = brdf.albedo(m, wo, samples=samples, seed=3)[0]
    w = brdf.sample(m, np.tile(wo, (samples, 1)), rng.random((samples, 3)))["weight"][:, 0]
    # Two independent estimates: within 5 standard errors of their difference.
    assert abs(a - x.mean()) < 5 * np.sqrt(x.var() / n + w.var() / samples), (a, x.mean())


@pytest.mark.parametrize("bad, key", [
    ({"brdf": "ward", "rho_d": 0.5, "rho_s": 1.5, "alpha": 0.1}, "rho_s"),
    ({"brdf": "ward", "rho_d": 0.5, "rho_s": 0.1}, "alpha"),
    ({"brdf": "ward", "rho_d": 0.5, "rho_s": 0.1, "alpha": 0.1, "shine": 2}, "shine"),
    ({"brdf": "phong", "rho_d": 0.5}, "brdf"),
    ({"brdf": "ggx_aniso", "rho_d": 0.5, "rho_s": 0.1, "alpha_x": 0.1, "alpha_y": -1},
     "alpha_y"),
    ({"brdf": "lambert", "rho_d": 0.5, "diffuse": "oren_nayar"}, "sigma"),
    ({"brdf": "emitter", "radiance": 1}, "brdf"),
])
def test_bad_material_raises_input_error_naming_the_key(bad, key):
    wi = np.array([[0.0, 0.0, 1.0]])
    with pytest.raises(igi.InputError, match=key) as raised:
        brdf.evaluate(bad, wi, wi)
    assert raised.value.problems and any(key in line for line in raised.value.problems)


def test_bad_shapes_raise_input_error():
    m = material("lambert")
    with pytest.raises(igi.InputError, match="wi"):
        brdf.evaluate(m, np.zeros((4, 2)), np.zeros((4, 3)))
    with pytest.raises(igi.InputError, match="same number of rows"):
        brdf.evaluate(m, np.zeros((4, 3)), np.zeros((5, 3)))
    with pytest.raises(igi.InputError, match="tangent"):
        brdf.evaluate(material("ward_aniso"), np.eye(3), np.eye(3), normal=[0, 0, 1])
