#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets (tests/fuzz/corpus/<target>/) and the texture the
scene seeds name (tests/fuzz/files/texture.png): small valid inputs taken from the shipped boards,
rigs and scenes or made here, and near-valid ones (a field cut short, a size claimed but not
there). Deterministic; run it again after a format changes and commit what it writes.

    tests/fuzz/make_seeds.py

The bundle seeds are signed with Python's `cryptography` (Debian: python3-cryptography).
"""
import base64
import hashlib
import json
import pathlib
import shutil
import struct
import zlib

FUZZ = pathlib.Path(__file__).resolve().parent
SRC = FUZZ.parent.parent
CORPUS = FUZZ / "corpus"
FILES = FUZZ / "files"
# Paths as the board and scene targets see them: relative to tests/fuzz/files.
RIG_FROM_FILES = "../../../boards/sim/"
MESHES_FROM_FILES = "../../unit/testdata/meshes/"


def write(target, name, data):
    path = CORPUS / target / name
    path.write_bytes(data if isinstance(data, bytes) else data.encode())


def png(width, height, colour_type, bit_depth, rows, extra=()):
    """A PNG with filter 0 on every row; `rows` is the raw bytes of each row."""
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    raw = b"".join(b"\0" + row for row in rows)
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr)
    for kind, data in extra:
        out += chunk(kind, data)
    return out + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


def png_seeds():
    rgb = [bytes(sum(((x * 60, y * 80, 255 - x * 60) for x in range(4)), ())) for y in range(3)]
    write("png", "rgb8_4x3.png", png(4, 3, 2, 8, rgb))
    grey16 = [struct.pack(">3H", 0, 9000 + y, 65535) for y in range(2)]
    write("png", "grey16_3x2.png", png(3, 2, 0, 16, grey16))
    write("png", "grey8_2x2.png", png(2, 2, 0, 8, [b"\x00\xff", b"\x80\x40"]))
    palette = [(b"PLTE", bytes((255, 0, 0, 0, 255, 0, 0, 0, 255))), (b"tRNS", b"\x80")]
    write("png", "palette4_4x2.png", png(4, 2, 3, 8, [b"\x00\x01\x02\x00", b"\x02\x01\x00\x01"],
                                         palette))
    write("png", "rgba16_1x1.png", png(1, 1, 6, 16, [struct.pack(">4H", 1, 2, 3, 65535)]))
    write("png", "grey_alpha_2x1_gamma.png",
          png(2, 1, 4, 8, [b"\x10\x20\x30\x40"], [(b"gAMA", struct.pack(">I", 45455))]))
    # Near-valid: a size claimed with no data behind it, data cut short, a wrong CRC.
    write("png", "claims_20000x20000.png", png(20000, 20000, 2, 8, []))
    whole = png(4, 3, 2, 8, rgb)
    write("png", "truncated.png", whole[:-20])
    write("png", "bad_crc.png", whole[:29] + b"\0\0\0\0" + whole[33:])
    # What png_fuzz found: a zTXt chunk claiming 738 MB, the file ending inside its frame.
    header = png(3, 2, 0, 16, [])[:33]
    write("png", "ztxt_cut_in_frame.png", header + struct.pack(">I", 738197525) + b"zTXtc")
    write("png", "empty_chunk_cut_in_frame.png", header + b"\0\0\0\0IDAT\0")


def json_seeds():
    for rig in sorted((SRC / "boards").glob("*/rig*.json")):
        write("rig", f"{rig.parent.name}_{rig.name}", rig.read_text())
    rig = json.loads((SRC / "boards/sim/rig_2proj_1cam.json").read_text())
    near = json.loads(json.dumps(rig))
    near["cameras"][0]["K"] = near["cameras"][0]["K"][:8]
    write("rig", "near_short_K.json", json.dumps(near))
    near = json.loads(json.dumps(rig))
    near["projectors"][1]["id"] = near["projectors"][0]["id"]
    write("rig", "near_duplicate_id.json", json.dumps(near))

    for board in sorted((SRC / "boards").glob("*/board.json")):
        value = json.loads(board.read_text())
        value["rig"] = RIG_FROM_FILES + pathlib.Path(value["rig"]).name
        write("board", f"{board.parent.name}.json", json.dumps(value, indent=1))
    value = json.loads((SRC / "boards/sim/board.json").read_text())
    value["rig"] = RIG_FROM_FILES + "rig_2proj_2cam.json"
    value["sim"] = {"replay": ".", "seed": 3}
    write("board", "near_replay.json", json.dumps(value))
    value["cameras"] = value["cameras"][:1]
    write("board", "near_one_camera_short.json", json.dumps(value))

    for scene in sorted((SRC / "hal/sim/scenes").glob("*.json")):
        value = json.loads(scene.read_text())
        for obj in value["objects"]:
            shape = obj.get("shape", {})
            if shape.get("type") == "mesh":
                shape["path"] = MESHES_FROM_FILES + "square.ply"
        write("scene", scene.name, json.dumps(value, indent=1))
    write("scene", "mesh_obj_texture.json", json.dumps({
        "format": "stripemux-scene/1",
        "objects": [
            {"name": "obj", "shape": {"type": "mesh", "path": MESHES_FROM_FILES + "square.obj"},
             "pose": {"t": [0, 0, 1], "rotation_deg": [0, 90, 0]},
             "albedo": {"texture": {"path": "texture.png", "width_m": 0.1, "height_m": 0.1}}},
            {"shape": {"type": "box", "size_m": [0.1, 0.1, 0.1]},
             "motion": {"velocity_m_per_frame": [0.002, 0, 0]}}]}))
    write("scene", "realism.json", json.dumps({
        "format": "stripemux-scene/1",
        "lighting": {"projector_black_level": 0.002, "projector_gamma": 2.2},
        "camera_response": {"response_gamma": 2.2, "vignetting": 0.3, "bayer": "rggb",
                            "exposure": 0.5, "exposure_samples": 4},
        "objects": [
            {"shape": {"type": "sphere", "radius_m": 0.1}, "pose": {"t": [0, 0, 0.8]},
             "motion": {"velocity_m_per_frame": [0.002, 0, 0]},
             "albedo": {"rgb": [0.5, 0.5, 0.5], "specular": 0.3, "shininess": 200}}]}))
    write("scene", "near_minimal.json",
          '{"format": "stripemux-scene/1", "objects": [{"shape": {"type": "plane"}}]}')


def rvl(values):
    """RVL as docs/protocol.md describes it (firmware/protocol/src/rvl.cpp writes the same)."""
    nibbles = []

    def code(value):
        while True:
            nibble = value & 7
            value >>= 3
            nibbles.append(nibble | (8 if value else 0))
            if not value:
                return

    previous = 0
    i = 0
    while i < len(values):
        zeros = 0
        while i < len(values) and values[i] == 0:
            zeros, i = zeros + 1, i + 1
        start = i
        while i < len(values) and values[i] != 0:
            i += 1
        code(zeros)
        code(i - start)
        for value in values[start:i]:
            delta = value - previous
            code(((delta << 1) ^ (delta >> 31)) & 0xFFFFFFFF)
            previous = value
    if len(nibbles) % 2:
        nibbles.append(0)
    return bytes(nibbles[k] << 4 | nibbles[k + 1] for k in range(0, len(nibbles), 2))


def range_frame(camera, compression, width, height, depth):
    return struct.pack("<BBHHQqqII", camera, compression, width, height, 7, 1000, 2000,
                       100000, 850) + depth


def confidence_frame(camera, compression, width, height, depth, confidence):
    """Message 9's payload: range-frame's fields, depth_bytes u32, the depth, the confidence."""
    return (range_frame(camera, compression, width, height, b"") + struct.pack("<I", len(depth)) +
            depth + confidence)


def range_seeds():
    width, height = 5, 3
    values = [0 if k % 4 == 0 else 9000 + 37 * k for k in range(width * height)]
    # The announcement the target reads first: cameras - 1, width - 1 and height - 1 (u16 LE).
    announce = struct.pack("<BHH", 1, width - 1, height - 1)
    raw = struct.pack(f"<{width * height}H", *values)
    write("range_frame", "raw_5x3.bin", announce + range_frame(1, 0, width, height, raw))
    write("range_frame", "rvl_5x3.bin", announce + range_frame(0, 1, width, height, rvl(values)))
    write("range_frame", "rvl_zeros_5x3.bin",
          announce + range_frame(0, 1, width, height, rvl([0] * (width * height))))
    write("range_frame", "near_claims_65535x65535.bin",
          announce + range_frame(0, 1, 65535, 65535, b""))
    write("range_frame", "near_camera_2_of_2.bin", announce + range_frame(2, 1, width, height,
                                                                          rvl(values)))
    # Frames with the confidence plane (message 9): bit 7 of the announcement's first byte.
    confidence = [0 if k % 4 == 0 else 200 + k for k in range(width * height)]
    announce9 = struct.pack("<BHH", 0x81, width - 1, height - 1)
    raw9 = confidence_frame(1, 0, width, height, raw, bytes(confidence))
    rvl9 = confidence_frame(0, 1, width, height, rvl(values), rvl(confidence))
    write("range_frame", "confidence_raw_5x3.bin", announce9 + raw9)
    write("range_frame", "confidence_rvl_5x3.bin", announce9 + rvl9)
    write("range_frame", "near_confidence_short_5x3.bin", announce9 + raw9[:-1])
    # Raw-frame bands (bit 6 of the announcement's first byte; bit 5: projector mask 1), two
    # records of [length u16, band] that complete one 5×3 camera.
    def band(first_row, rows):
        pixels = bytes((7 * k) & 0xFF for k in range(3 * width * rows))
        payload = struct.pack("<BIHHHHQq", 0, 1, width, height, first_row, rows, 3, 1000) + pixels
        return struct.pack("<H", len(payload)) + payload
    announce_raw = struct.pack("<BHH", 0x60, width - 1, height - 1)
    write("range_frame", "raw_bands_5x3.bin", announce_raw + band(0, 2) + band(2, 1))
    write("range_frame", "near_raw_row_twice_5x3.bin", announce_raw + band(0, 2) + band(1, 2))

    # The protocol target: a first byte with bit 7 set asks it to seal [type, length u16,
    # payload] records into messages with correct headers.
    def record(kind, payload):
        return struct.pack("<BH", kind, len(payload)) + payload
    hello = struct.pack("<H", 14) + b"stripemux test"
    frames = (record(1, hello) + record(5, range_frame(0, 1, width, height, rvl(values))) +
              record(6, b"") + record(5, range_frame(1, 0, width, height, raw)) +
              record(3, b"\x01\x01") + record(9, rvl9) + record(9, raw9))
    write("protocol", "sealed_hello_frames.bin", b"\x87" + frames)
    write("protocol", "sealed_frame_claims_65535.bin",
          b"\x90" + record(5, range_frame(0, 1, 65535, 65535, b"\x00")))
    # capture-raw, then the bands of a 5×3 raw frame (rows 0–1 and 2), as docs/protocol.md says.
    def raw_band(first_row, rows):
        pixels = bytes((7 * k) & 0xFF for k in range(3 * width * rows))
        return struct.pack("<BIHHHHQq", 0, 1, width, height, first_row, rows, 3, 1000) + pixels
    write("protocol", "sealed_raw_capture.bin",
          b"\x87" + record(1, hello) + record(10, struct.pack("<I", 1)) +
          record(11, raw_band(0, 2)) + record(11, raw_band(2, 1)))
    write("protocol", "sealed_raw_band_past_height.bin", b"\x90" + record(11, raw_band(2, 2)[:-15]))
    # get-turntable, turn-turntable by -90 degrees, the turntable's answer (docs/protocol.md).
    turntable = struct.pack("<BIqqq", 1, 3200, -800, -90_000_000, 123_456_789)
    write("protocol", "sealed_turntable.bin",
          b"\x87" + record(1, hello) + record(29, b"") +
          record(31, struct.pack("<Bq", 0, -90_000_000)) + record(30, turntable))
    write("protocol", "sealed_turntable_bad_mode.bin",
          b"\x90" + record(31, struct.pack("<Bq", 7, 1)) + record(30, turntable[:-1]))


def config_seeds():
    """Settings for the simulated board: each key alone, all of them with its rig, and near-valid
    ones (a window with min above max, a rig cut short)."""
    rig = json.loads((SRC / "boards/sim/rig_2proj_2cam.json").read_text())
    head = {"format": "stripemux-config/1"}
    write("config", "empty.json", json.dumps(head))
    write("config", "fps.json", json.dumps({**head, "fps": 12}))
    write("config", "window.json", json.dumps({**head, "depth_min_m": 0.3, "depth_max_m": 1.5,
                                               "confidence_min": 100}))
    write("config", "window_empty.json", json.dumps({**head, "depth_min_m": 2, "depth_max_m": 1}))
    write("config", "all.json", json.dumps({**head, "fps": 7, "compression": "none",
                                            "depth_max_m": 2, "rig": rig}, indent=1))
    write("config", "rig_cut.json", json.dumps({**head, "rig": rig})[:900])


# The fuzzer's trusted test key (bundle_fuzz.cpp): Ed25519 from the seed of 32 bytes of 1, its id
# the first 8 bytes of BLAKE2b-256 of the seed, as smx::update::keyPairFromSeed makes it.
BUNDLE_KEY_SEED = bytes([1] * 32)


def bundle(manifest, payload, seed=BUNDLE_KEY_SEED):
    """A stripemux-bundle/1 file (docs/update.md): header, manifest, payload, signature, trailer."""
    from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey
    key = Ed25519PrivateKey.from_private_bytes(seed)
    key_id = hashlib.blake2b(seed, digest_size=32).digest()[:8]
    manifest = manifest.encode()
    signed = b"SMXBNDL1" + struct.pack("<IIQ", len(manifest), 0, len(payload)) + manifest + payload
    signature = key.sign(hashlib.blake2b(signed).digest())
    comment = b"stripemux-bundle/1"
    text = (b"untrusted comment: stripemux signature\n" +
            base64.b64encode(b"ED" + key_id + signature) + b"\ntrusted comment: " + comment +
            b"\n" + base64.b64encode(key.sign(signature + comment)) + b"\n")
    return signed + text + struct.pack("<I", len(text)) + b"SMXSIGN1"


def manifest(files, version="1.2.3", boards=("sim",), allow_downgrade=False):
    return json.dumps({"format": "stripemux-bundle/1", "version": version, "boards": list(boards),
                       "allow_downgrade": allow_downgrade,
                       "files": [{"name": name, "size": len(data), "mode": mode,
                                  "blake2b": hashlib.blake2b(data, digest_size=32).hexdigest()}
                                 for name, mode, data in files]}, indent=1)


def bundle_seeds():
    files = [("bin/stripemuxd", "0755", b"#!/bin/sh\necho firmware\n"),
             ("boards/sim/board.json", "0644", b'{"format": "stripemux-board/1"}\n')]
    payload = b"".join(data for _, _, data in files)
    whole = bundle(manifest(files), payload)
    write("bundle", "valid_sim.bundle", whole)
    write("bundle", "valid_downgrade.bundle",
          bundle(manifest(files, "0.9.0", ("rpi4", "sim"), True), payload))
    write("bundle", "empty.bundle", bundle(manifest([]), b""))
    # Near-valid: cut short, a signed byte changed, another key, another board.
    write("bundle", "near_truncated.bundle", whole[:-40])
    changed = bytearray(whole)
    changed[30] ^= 1
    write("bundle", "near_bad_signature.bundle", bytes(changed))
    write("bundle", "near_other_key.bundle", bundle(manifest(files), payload, bytes([2] * 32)))
    write("bundle", "near_other_board.bundle", bundle(manifest(files, boards=("rpi4",)), payload))
    # Manifests the fuzzer seals with the test key itself: "MANIFEST\0PAYLOAD".
    write("bundle", "manifest_valid.txt", manifest(files).encode() + b"\0" + payload)
    write("bundle", "manifest_hostile_name.txt",
          manifest([("../escape", "0644", b"x")]).encode() + b"\0x")
    write("bundle", "manifest_file_and_dir.txt",
          manifest([("a", "0644", b"x"), ("a/b", "0644", b"y")]).encode() + b"\0xy")


def pairing_seeds():
    """[type, length u16, payload] records of messages 21-28 (docs/security.md)."""
    def record(kind, payload):
        return struct.pack("<BH", kind, len(payload)) + payload
    key = bytes(range(32))
    write("pairing", "secure_hello_accept.bin", record(21, key + key) + record(22, key * 2))
    write("pairing", "pairing_exchange.bin",
          record(27, b"") + record(28, bytes([3]) + struct.pack("<H", 300) + bytes([8])) +
          record(23, key * 2) + record(24, key * 3) + record(25, key) + record(26, b""))
    write("pairing", "short_and_long.bin", record(21, key) + record(24, key * 3 + b"x") +
          record(28, bytes([4, 0, 0, 9])))


def main():
    for target in ("protocol", "rig", "board", "scene", "png", "range_frame", "config", "bundle",
                   "pairing"):
        shutil.rmtree(CORPUS / target, ignore_errors=True)
        (CORPUS / target).mkdir(parents=True)
    FILES.mkdir(exist_ok=True)
    checker = [bytes(sum(((255 * ((x + y) % 2),) * 3 for x in range(8)), ())) for y in range(8)]
    (FILES / "texture.png").write_bytes(png(8, 8, 2, 8, checker))
    png_seeds()
    json_seeds()
    range_seeds()
    config_seeds()
    bundle_seeds()
    pairing_seeds()


if __name__ == "__main__":
    main()
