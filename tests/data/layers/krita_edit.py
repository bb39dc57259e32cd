"""Krita edits an OpenRaster file written by `mcctrace render --layers` the way a user would,
and saves it as OpenRaster (tests/data/layers/README.md says how it is run). Paths come from
the environment: MCC_IN (the views.ora to open), MCC_OUT (the .ora to save)."""

import os

from krita import InfoObject, Krita


def layer(doc, suffix):
    return next(n for n in doc.rootNode().childNodes() if n.name().endswith(suffix))


def scale_alpha(node, w, h, factor):
    """Multiplies the layer's alpha by factor(x, y), rounded (Krita's RGBA U8 is BGRA)."""
    data = bytearray(node.pixelData(0, 0, w, h))
    for y in range(h):
        for x in range(w):
            k = 4 * (y * w + x) + 3
            data[k] = int(round(data[k] * factor(x, y)))
    node.setPixelData(bytes(data), 0, 0, w, h)


def main(args=None):
    app = Krita.instance()
    doc = app.openDocument(os.environ["MCC_IN"])
    doc.setBatchmode(True)
    w, h = doc.width(), doc.height()
    root = doc.rootNode()
    cam1 = layer(doc, "(camera 1)")
    cam2 = layer(doc, "(camera 2)")
    # A linear feather: camera 1 opaque up to x = 24, transparent from x = 40.
    scale_alpha(cam1, w, h, lambda x, y: min(1.0, max(0.0, (40 - (x + 0.5)) / 16)))
    # Camera 2 into a group at 90 % opacity, with its top right corner erased.
    scale_alpha(cam2, w, h, lambda x, y: 0.0 if x >= 44 and y < 12 else 1.0)
    group = doc.createGroupLayer("right side")
    root.addChildNode(group, cam2)
    cam2_copy = cam2.duplicate()
    root.removeChildNode(cam2)
    group.addChildNode(cam2_copy, None)
    cam2_copy.setName(cam2.name())
    group.setOpacity(230)
    # An opaque 10x6 patch of camera 1 at (50, 30), and a hidden sketch layer on top.
    patch = doc.createNode("camera 1 patch", "paintlayer")
    root.addChildNode(patch, None)
    patch.setPixelData(bytes([255, 255, 255, 255]) * 60, 50, 30, 10, 6)
    sketch = doc.createNode("sketch", "paintlayer")
    root.addChildNode(sketch, None)
    sketch.setPixelData(bytes([0, 0, 255, 255]) * (w * h), 0, 0, w, h)
    sketch.setVisible(False)
    doc.refreshProjection()
    print("layers:", [n.name() for n in root.childNodes()])
    print("saved:", doc.exportImage(os.environ["MCC_OUT"], InfoObject()))
