"""Alignment files that place several range scans in one frame: MeshLab's ``.aln`` (written by
its Align tool), its project ``.mlp`` (*File > Save Project*: each layer's file and matrix) and
the Stanford ``.conf``. Each gives, per scan, its file and the 4x4 matrix M that takes the
scan's points p to the common frame (M @ [p, 1]), the layer matrix MeshLab would give it."""
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np

SUFFIXES = (".aln", ".mlp", ".conf")  # the files read_alignment reads


def read_alignment(path) -> list:
    """[(scan path, (4, 4) matrix)] from a ``.aln``, ``.mlp`` or ``.conf`` file; scan paths are
    relative to the alignment file's folder. Raises ValueError with the line at fault."""
    path = Path(path)
    text = path.read_text()
    if path.suffix.lower() == ".conf":
        scans = _conf(text.splitlines(), path)
    elif path.suffix.lower() == ".aln":
        scans = _aln(text.splitlines(), path)
    elif path.suffix.lower() == ".mlp":
        scans = _mlp(text, path)
    else:
        raise ValueError(f"{path}: not an alignment file (MeshLab .aln or .mlp, or Stanford .conf)")
    if not scans:
        raise ValueError(f"{path}: lists no scans")
    for name, matrix in scans:
        _check_rigid(matrix, f"{path}: scan {name}")
    return [(path.parent / name, matrix) for name, matrix in scans]


def _check_rigid(matrix, where):
    """Raises ValueError unless matrix is a rigid motion: an alignment moves and turns a scan,
    never scales, shears or projects it (a matrix written transposed has its translation in the
    last row)."""
    if not np.all(np.isfinite(matrix)):
        raise ValueError(f"{where}: the matrix has a NaN or infinite entry")
    if not np.allclose(matrix[3], [0, 0, 0, 1], atol=1e-6):
        raise ValueError(f"{where}: the matrix's last row is {' '.join(f'{x:g}' for x in matrix[3])}, not 0 0 0 1: "
                         "not a rigid motion (was it written transposed?)")
    stretch = np.linalg.svd(matrix[:3, :3], compute_uv=False)
    if np.abs(stretch - 1).max() > 1e-3 or np.linalg.det(matrix[:3, :3]) < 0:
        raise ValueError(f"{where}: the matrix is not a rigid motion (it scales, shears or mirrors the scan by "
                         f"up to {100 * np.abs(stretch - 1).max():.3g}%); an alignment only moves and turns scans")


def _conf(lines, path):
    """Stanford: ``bmesh FILE tx ty tz qx qy qz qw`` means world = R(q)^-1 p + t."""
    scans = []
    for number, line in enumerate(lines, 1):
        words = line.split()
        if not words or words[0] != "bmesh":
            continue  # camera, comments
        try:
            t = np.array(words[2:5], dtype=float)
            qx, qy, qz, qw = (float(w) for w in words[5:9])
        except ValueError:
            raise ValueError(f"{path}:{number}: expected 'bmesh FILE tx ty tz qx qy qz qw'") from None
        if len(words) != 9:
            raise ValueError(f"{path}:{number}: expected 'bmesh FILE tx ty tz qx qy qz qw'")
        norm = np.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
        if not norm > 0:
            raise ValueError(f"{path}:{number}: the rotation quaternion (qx qy qz qw) is zero")
        qx, qy, qz, qw = qx / norm, qy / norm, qz / norm, qw / norm
        rotation = np.array([
            [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
            [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
            [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]])
        matrix = np.eye(4)
        matrix[:3, :3] = rotation.T  # the inverse of a rotation
        matrix[:3, 3] = t
        scans.append((words[1], matrix))
    return scans


def _aln(lines, path):
    """MeshLab: the scan count, then per scan its file, a '#' line and 4 rows of its matrix."""
    lines = [line.strip() for line in lines if line.strip()]
    try:
        count = int(lines[0])
        scans = []
        for i in range(count):
            block = lines[1 + 6 * i: 7 + 6 * i]
            matrix = np.array([[float(x) for x in row.split()] for row in block[2:6]])
            if matrix.shape != (4, 4):
                raise ValueError
            scans.append((block[0], matrix))
    except (ValueError, IndexError):
        raise ValueError(f"{path}: not a MeshLab alignment: a scan count, then per scan its file, '#' and "
                         "4 rows of 4 numbers") from None
    return scans


def _mlp(text, path):
    """MeshLab project: per visible layer (``<MLMesh visible="1" filename=...>``) its file and its
    ``<MLMatrix44>`` (16 numbers, row by row; none: the identity). Hidden layers are left out, as
    MeshLab's *Flatten Visible Layers* leaves them out of a merge."""
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as error:
        raise ValueError(f"{path}: not a MeshLab project ({error})") from None
    scans = []
    for layer in root.iter("MLMesh"):
        name = layer.get("filename")
        if not name:
            raise ValueError(f"{path}: a layer ({layer.get('label', 'no label')}) has no filename")
        if layer.get("visible", "1") == "0":
            continue
        element = layer.find("MLMatrix44")
        try:
            matrix = np.eye(4) if element is None else np.array(element.text.split(), dtype=float).reshape(4, 4)
        except (ValueError, AttributeError):
            raise ValueError(f"{path}: layer {name}: its MLMatrix44 is not 16 numbers") from None
        scans.append((name, matrix))
    return scans
