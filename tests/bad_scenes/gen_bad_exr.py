"""Writes assets/nan.exr: a 2x1 uncompressed scanline OpenEXR (float R, G, B) whose second texel
holds a NaN and an infinity, for the environment-map bad-input case. Run it in this folder."""

import struct


def attr(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def main():
    width, height = 2, 1
    channels = b"".join(
        c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR"
    ) + b"\0"
    window = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = b"".join([
        attr("channels", "chlist", channels),
        attr("compression", "compression", b"\0"),
        attr("dataWindow", "box2i", window),
        attr("displayWindow", "box2i", window),
        attr("lineOrder", "lineOrder", b"\0"),
        attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        attr("screenWindowWidth", "float", struct.pack("<f", 1.0)),
    ]) + b"\0"
    start = b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + header
    nan, inf = float("nan"), float("inf")
    texels = {"R": [0.5, nan], "G": [0.5, inf], "B": [0.5, 0.5]}
    data = b"".join(struct.pack("<ff", *texels[c]) for c in "BGR")
    line = struct.pack("<ii", 0, len(data)) + data
    offset = len(start) + 8 * height
    with open("assets/nan.exr", "wb") as f:
        f.write(start + struct.pack("<Q", offset) + line)


if __name__ == "__main__":
    main()
