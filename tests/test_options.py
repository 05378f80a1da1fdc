"""options.py spells every enum label as the loaded plugin does, in the plugin's order."""
import xml.etree.ElementTree as ET

import pymeshlab
import pytest

import implicit_boundaries
from implicit_boundaries.options import ENUMS, NORMAL_NEIGHBOURS
from shapes import fibonacci_sphere


@pytest.fixture(scope="module")
def plugin_enums(plugin, tmp_path_factory):
    """{parameter: [labels in the plugin's order]} for every enum parameter of the filter.

    pymeshlab lists a filter's parameters only with their current values (print_filter_parameter_list,
    filter_parameter_values); the filter script MeshLab records for a run holds each enum's
    labels (enum_val0, enum_val1, ...), so the filter is run once on a small sphere.
    """
    points = fibonacci_sphere(500)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=points, v_normals_matrix=points))
    implicit_boundaries.apply(ms, resolution=10)
    script = tmp_path_factory.mktemp("script") / "filter.mlx"
    ms.save_filter_script(str(script))
    (run,) = ET.parse(script).getroot().iter("filter")
    return {p.get("name"): [p.get(f"enum_val{i}") for i in range(int(p.get("enum_cardinality")))]
            for p in run.iter("Param") if p.get("type") == "RichEnum"}


def test_every_enum_parameter_has_its_labels_in_options(plugin_enums):
    assert set(plugin_enums) == set(ENUMS)


@pytest.mark.parametrize("parameter", sorted(ENUMS))
def test_the_labels_match_the_plugin_in_order(plugin_enums, parameter):
    labels = ENUMS[parameter]
    assert list(labels.LABELS) == plugin_enums[parameter]
    named = [value for name, value in vars(labels).items() if name.isupper() and name != "LABELS"]
    assert sorted(named) == sorted(labels.LABELS)  # no label left out of LABELS


def test_the_first_label_and_the_normal_neighbours_are_the_defaults(plugin):
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=fibonacci_sphere(50)))
    defaults = ms.filter_parameter_values(implicit_boundaries.FILTER_NAME)  # an enum's default as its index
    assert {name: defaults[name] for name in ENUMS} == {name: 0 for name in ENUMS}
    assert defaults["normal_neighbours"] == NORMAL_NEIGHBOURS
