"""The built-in parametric through-hole parts: their default dimensions and mass, and the
primitives each is built of, for collision (leads merged into one thin plate per row) and for
display (every lead). Dimensions in, primitives out; no mesh stack."""

from collections.abc import Mapping

from ..errors import check_int, check_number, InvalidArgument, UnknownPart
from .primitives import box, cylinder, Primitive
from .spec import check_material, MAX_PART_SIZE, MIN_PART_SIZE, PartSpec

# name -> (default dimensions in metres, default mass in kg, description)
BUILTIN_MODELS: dict[str, tuple[dict[str, float], float, str]] = {
    'radial_capacitor': ({
        'body_diameter': 0.005,
        'body_length': 0.011,
        'lead_diameter': 0.0005,
        'lead_length': 0.015,
        'lead_pitch': 0.002,
    }, 0.0004, 'cylindrical body along +Z, two leads along -Z spaced along X'),
    'to220': ({
        'body_width': 0.010,
        'body_thickness': 0.0045,
        'body_height': 0.009,
        'tab_height': 0.0065,
        'tab_thickness': 0.0013,
        'lead_width': 0.0008,
        'lead_thickness': 0.0005,
        'lead_length': 0.013,
        'lead_pitch': 0.00254,
    }, 0.002, 'body box, metal tab above it (+Z) at the back (-Y), three leads along -Z'),
    'dip': ({
        'body_length': 0.0094,
        'body_width': 0.00635,
        'body_height': 0.0033,
        'pins_per_row': 4.0,
        'pin_pitch': 0.00254,
        'row_spacing': 0.00762,
        'pin_length': 0.0035,
        'pin_width': 0.0005,
        'pin_thickness': 0.00025,
    }, 0.0005, 'body box, two rows of pins along -Z, rows spaced along Y, pins along X'),
}


def _radial_capacitor(d: Mapping[str, float]):
    body_r, body_l = d['body_diameter'] / 2, d['body_length']
    lead_r, lead_l, pitch = d['lead_diameter'] / 2, d['lead_length'], d['lead_pitch']
    if pitch / 2 + lead_r > body_r:
        raise InvalidArgument('part.dimensions.lead_pitch', pitch,
                              f'puts the leads outside the body (max {2 * (body_r - lead_r):g})')
    lead_z = -(body_l + lead_l) / 2
    visual = [cylinder(body_r, body_l),
              cylinder(lead_r, lead_l, (pitch / 2, 0, lead_z)),
              cylinder(lead_r, lead_l, (-pitch / 2, 0, lead_z))]
    # The two leads collide as their convex hull (a thin plate): one shape instead of two,
    # and no thin gap for another part's lead to jitter in.
    collision = [visual[0], box((pitch / 2 + lead_r, lead_r, lead_l / 2), (0, 0, lead_z))]
    return collision, visual


def _to220(d: Mapping[str, float]):
    w, t, h = d['body_width'], d['body_thickness'], d['body_height']
    tab_h, tab_t = d['tab_height'], d['tab_thickness']
    lw, lt, ll, pitch = d['lead_width'], d['lead_thickness'], d['lead_length'], d['lead_pitch']
    if tab_t > t:
        raise InvalidArgument('part.dimensions.tab_thickness', tab_t,
                              f'must be <= body_thickness {t:g}')
    if 2 * pitch + lw > w:
        raise InvalidArgument('part.dimensions.lead_pitch', pitch,
                              f'puts the leads outside the body (max {(w - lw) / 2:g})')
    body = box((w / 2, t / 2, h / 2))
    tab = box((w / 2, tab_t / 2, tab_h / 2), (0, -(t - tab_t) / 2, (h + tab_h) / 2))
    lead_z = -(h + ll) / 2
    leads = [box((lw / 2, lt / 2, ll / 2), (k * pitch, 0, lead_z)) for k in (-1, 0, 1)]
    collision = [body, tab, box((pitch + lw / 2, lt / 2, ll / 2), (0, 0, lead_z))]
    return collision, [body, tab, *leads]


def _dip(d: Mapping[str, float]):
    n = check_int('part.dimensions.pins_per_row', d['pins_per_row'], low=1, high=64)
    bl, bw, bh = d['body_length'], d['body_width'], d['body_height']
    pitch, rows, pl = d['pin_pitch'], d['row_spacing'], d['pin_length']
    pw, pt = d['pin_width'], d['pin_thickness']
    span = (n - 1) * pitch + pw
    if span > bl:
        raise InvalidArgument('part.dimensions.pin_pitch', pitch,
                              f'with {n} pins per row needs body_length >= {span:g}')
    if not pt < rows <= 3 * bw:
        raise InvalidArgument('part.dimensions.row_spacing', rows,
                              f'must be within ({pt:g}, {3 * bw:g}]: above pin_thickness, '
                              'at most 3 * body_width')
    body = box((bl / 2, bw / 2, bh / 2))
    pin_z = -(bh + pl) / 2
    pins = [box((pw / 2, pt / 2, pl / 2), (-(n - 1) * pitch / 2 + k * pitch, s * rows / 2, pin_z))
            for s in (-1, 1) for k in range(n)]
    collision = [body] + [box((span / 2, pt / 2, pl / 2), (0, s * rows / 2, pin_z))
                          for s in (-1, 1)]
    return collision, [body, *pins]


_BUILDERS = {'radial_capacitor': _radial_capacitor, 'to220': _to220, 'dip': _dip}


def builtin(spec: PartSpec) -> tuple[dict[str, float], float, list[Primitive],
                                      list[Primitive]]:
    """A built-in model's dimensions (m, its defaults with the spec's overrides), mass (kg),
    collision primitives and visual primitives, checked. Raises InvalidArgument naming the
    dimension or material field, UnknownPart for a name that is no model."""
    if spec.model not in BUILTIN_MODELS:
        raise UnknownPart(f'part.model: {spec.model!r} is not a part model '
                          f'(known: {", ".join(sorted(BUILTIN_MODELS))}, mesh)')
    defaults, default_mass, _ = BUILTIN_MODELS[spec.model]
    unknown = sorted(set(spec.dimensions) - set(defaults))
    if unknown:
        raise InvalidArgument(f'part.dimensions.{unknown[0]}', spec.dimensions[unknown[0]],
                              f'is not a dimension of {spec.model} '
                              f'(known: {", ".join(sorted(defaults))})')
    dims = {}
    for name, default in defaults.items():
        value = spec.dimensions.get(name, default)
        if name == 'pins_per_row':
            dims[name] = float(check_int(f'part.dimensions.{name}', value, low=1, high=64))
        else:
            dims[name] = check_number(f'part.dimensions.{name}', value, low=MIN_PART_SIZE,
                                      high=MAX_PART_SIZE)
    mass = check_material(spec, default_mass)
    collision, visual = _BUILDERS[spec.model](dims)
    return dims, mass, collision, visual
