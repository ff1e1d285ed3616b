"""The calibration's harmonic models and YAML files as the Python tools read them (hrg_report.py,
plot_calibration.py, make_doc_figures.py): one evaluation of a harmonic model, one interpolation of a
frequency-dependent result across its nodes, one YAML reader. A module beside the scripts, not a
program.

A harmonic model is a map as the calibration report and the parameter file write it: mean, orders,
cos, sin (and mean_std, cos_std, sin_std for a fit's standard errors):
    value(theta) = mean + sum_k cos_k cos(k theta) + sin_k sin(k theta).
"""
import io
import math
import re

import yaml

import hrg_output_file
from hrg_output_file import shown

MAX_YAML_BYTES = 16 << 20  # a calibration report is well below 1 MiB; larger is not one


# ---------------------------------------------------------------------------------------------
# Harmonic models.

def model(estimate, theta):
    """The model's value at theta."""
    value = estimate["mean"]
    for k, a, b in zip(estimate["orders"], estimate["cos"], estimate["sin"]):
        value += a * math.cos(k * theta) + b * math.sin(k * theta)
    return value


def model_std(estimate, theta):
    """1-sigma of the model at theta from the coefficients' standard errors, taken as independent."""
    var = estimate["mean_std"] ** 2
    for k, sa, sb in zip(estimate["orders"], estimate["cos_std"], estimate["sin_std"]):
        var += (sa * math.cos(k * theta)) ** 2 + (sb * math.sin(k * theta)) ** 2
    return math.sqrt(var)


def spline_weights(nodes, f, natural):
    """Weights w_j with value(f) = sum_j w_j y_j: natural cubic spline or piecewise linear, end values
    held outside the nodes (as FrequencyInterpolator does)."""
    n = len(nodes)
    w = [0.0] * n
    if f <= nodes[0] or f >= nodes[-1]:
        w[0 if f <= nodes[0] else n - 1] = 1.0
        return w
    i = max(j for j in range(n - 1) if nodes[j] <= f)
    h = nodes[i + 1] - nodes[i]
    t = (f - nodes[i]) / h
    w[i], w[i + 1] = 1.0 - t, t
    if not natural or n < 3:
        return w
    # Second derivatives m = C y with m_0 = m_{n-1} = 0 from the interior equations T m = D y.
    m = n - 2
    T = [[0.0] * m for _ in range(m)]
    D = [[0.0] * n for _ in range(m)]
    for r in range(m):
        h0, h1 = nodes[r + 1] - nodes[r], nodes[r + 2] - nodes[r + 1]
        if r > 0:
            T[r][r - 1] = h0
        T[r][r] = 2.0 * (h0 + h1)
        if r < m - 1:
            T[r][r + 1] = h1
        D[r][r], D[r][r + 1], D[r][r + 2] = 6.0 / h0, -6.0 / h0 - 6.0 / h1, 6.0 / h1
    # Solve T C = D by Gaussian elimination (T is small and diagonally dominant).
    for c in range(m):
        for r in range(c + 1, m):
            factor = T[r][c] / T[c][c]
            T[r] = [a - factor * b for a, b in zip(T[r], T[c])]
            D[r] = [a - factor * b for a, b in zip(D[r], D[c])]
    C = [[0.0] * n for _ in range(m)]
    for r in reversed(range(m)):
        row = D[r][:]
        for c in range(r + 1, m):
            row = [a - T[r][c] * b for a, b in zip(row, C[c])]
        C[r] = [a / T[r][r] for a in row]
    curvature = [[0.0] * n] + C + [[0.0] * n]
    ci = h * h / 6.0 * ((1.0 - t) ** 3 - (1.0 - t))
    cj = h * h / 6.0 * (t ** 3 - t)
    return [w[k] + ci * curvature[i][k] + cj * curvature[i + 1][k] for k in range(n)]


def at_frequency(fits, nodes, f, natural):
    """The fitted coefficients of a frequency-dependent result (one model per node) interpolated at f."""
    w = spline_weights(nodes, f, natural)
    out = dict(fits[0])
    for key in ("mean",):
        out[key] = sum(wj * fit[key] for wj, fit in zip(w, fits))
    for key in ("cos", "sin"):
        out[key] = [sum(wj * fit[key][q] for wj, fit in zip(w, fits)) for q in range(len(fits[0][key]))]
    return out


# ---------------------------------------------------------------------------------------------
# YAML, as the package's C++ tools write and read it.

class DuplicateKeyError(yaml.YAMLError):
    pass


class Loader(yaml.SafeLoader):
    """YAML 1.2 numbers: yaml-cpp writes 1e-05, which PyYAML's YAML 1.1 rules would read as a string.
    A key given twice in one map is refused, as the package's C++ reader refuses it: PyYAML would
    silently keep the last one (a limit typed twice would drop the first)."""

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            first_line = {}
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue  # "<<: *base": keys given beside it override the merged ones
                key = self.construct_object(key_node, deep=True)
                try:
                    line = first_line.get(key)
                except TypeError:
                    continue  # an unhashable key: SafeLoader refuses it with its own message
                if line is not None:
                    raise DuplicateKeyError("key %s given more than once in the same map (lines %d and %d)" %
                                            (shown(key), line + 1, key_node.start_mark.line + 1))
                first_line[key] = key_node.start_mark.line
        return super().construct_mapping(node, deep)


Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
                    |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
                    |\.[0-9_]+(?:[eE][-+][0-9]+)?
                    |[-+]?\.(?:inf|Inf|INF)
                    |\.(?:nan|NaN|NAN))$""", re.X),
    list("-+0123456789."))


class YamlFileError(Exception):
    """A YAML file that cannot be read as a map; the message names what it is and its path."""


def one_line(text, limit=300):
    """A message on one line, cut to `limit` characters."""
    text = " ".join(str(text).split())
    return text if len(text) <= limit else "%s... (%d characters)" % (text[:limit], len(text))


def parse_yaml(text):
    """The YAML document in `text` (a parameter file embedded in a report) by the rules of Loader."""
    return yaml.load(text, Loader=Loader)


def read_yaml(path, what, max_bytes=MAX_YAML_BYTES):
    """The YAML map in `path`: a regular file of at most `max_bytes`, UTF-8, no key given twice;
    YamlFileError naming `what` and the path otherwise."""
    try:
        raw = hrg_output_file.read_regular_file(path, what, max_bytes)
    except hrg_output_file.PathRefused as e:
        raise YamlFileError(str(e))
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise YamlFileError("cannot read %s %s: not UTF-8 text (byte %d)" % (what, path, e.start))
    stream = io.StringIO(text)
    stream.name = path  # PyYAML's messages name the file
    try:
        data = yaml.load(stream, Loader=Loader)
    except DuplicateKeyError as e:
        raise YamlFileError("%s %s: %s" % (what, path, e))
    except yaml.YAMLError as e:
        raise YamlFileError("cannot read %s %s: %s" % (what, path, one_line(e)))
    except RecursionError:
        raise YamlFileError("cannot read %s %s: nested too deeply" % (what, path))
    if not isinstance(data, dict):
        raise YamlFileError("%s %s is not a YAML map" % (what, path))
    return data
