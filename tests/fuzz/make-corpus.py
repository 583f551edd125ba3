#!/usr/bin/env python3
# SPDX-License-Identifier: LGPL-2.1-or-later
"""Writes the seed corpora of the fuzz harnesses, corpus/<harness>/, from the test vectors
(tests/lib/test_payload.cc), samples/hello.pfap-hex and docs/examples/*.pfap. Run from
anywhere; it replaces the directories' contents. The files are committed: rerun it when the
sources change, and commit what it writes."""
import hashlib
import pathlib
import re
import shutil

FUZZ = pathlib.Path(__file__).resolve().parent
ROOT = FUZZ.parent.parent

# The hand-derived vectors of tests/lib/test_payload.cc (PayloadVectors), good payloads.
VECTORS = {
    "one_phoneme_end_of_text": "00 2A 06 43 CF",
    "draft_expression_example": "01 8A 00 00 A0 7D 0D 8C 00 00 78 7D 0C 07 05 00 06",
    "dynamic_recovery_extremes": "2C 61 01 38 80 00 04 94 9A 65 03 FF FB FF FF FF FA",
    "complete_recovery": "A2 06 00 01 90 00 07",
    "complete_recovery_all_zero": "82",
    "dynamic_recovery_nothing_to_recover": "04 00 00 00 02",
    "fap_between_phonemes": "00 01 00 10 15 27 00 00 04 00 14 02 00 20 22",
    # The canonical forms: negative zero, and PP set with C = 1.
    "negative_zero": "01 07 00 00 00 00 04 00 00 00 02",
    "complete_recovery_with_pp": "BE 06 00 01 90 00 07",
}
# A few bad ones from PayloadDecode.RefusesEachClassOfBadPayload, one per class.
BAD = {
    "truncated_phoneme": "00 00 00 00",
    "reserved_type_10": "40 00 00 00 02",
    "reserved_ib_01_in_recovery": "24 06 00 01 90 00 05 00 00 00 02",
    "dynamic_recovery_with_pp_000": "20 06 00 01 90 00 07 00 00 00 02",
    "fap_index_75": "01 96 00 01 90 00 04 00 00 00 02",
    "amplitude_2529601": "01 06 9A 65 04 00 04 00 00 00 02",
    "curve_zero": "01 06 00 01 90 00 00 00 00 00 02",
    "missing_final_phoneme": "00 00 00 00 00",
    "trailing_bytes": "00 00 00 00 02 00",
    "data_in_complete_recovery": "80 00 00 00 02",
    "unterminated_recovery": "24 06 00 01 90 00 04",
    "empty_packet": "02",
}

BOOKMARKS = [
    "<FAP 2 1 40 2 30 2000 3>",  # the draft's example
    "<FAP 2 1 40 0 0 500 1>",  # the TTS interface's, neutral second slot
    "<FAP 69 40 2000 3><FAP 70 30 2000 3>",  # the transformed form
    "<FAP 48 -20000 0 1>",
    "<FAP 74 2529600 16383 2>",
    "< FAP\t3 +100 0 1 >\n<FAP 3 -0 00 1>",
    "<FAP 2 6 2529600 6 -2529600 16383 3>",
    "<FAP 3 100 0 1",  # unterminated
    "<FAP 3 100 16384 1>",  # transition out of range
    "<FAP 1 0 0 1>",
    "<FAP 3 99999999999999999999 0 1>",
    "x <FAP 3 1 1 1>",
    "".join(f"<FAP {3 + i} {i} {i} 1>" for i in range(40)),
    "".join(f"<FAP {3 + i} {i} {i} 1>" for i in range(41)),
    "".join("<FAP 2 1 1 2 2 1 1>" for _ in range(40)),
]

TEXT_LINES = [
    "0 state complete",
    "0 state recovered <FAP 3 1 0 1>",
    "0 16 60 118 SWE",
    "0 16 60 118 -   # comment",
    "1 255 4095 510 SW <FAP 2 1 40 2 30 2000 3>\r",
    "9223372036850 0 0 0 -",  # near the time limit
    "9223372036855 0 0 0 -",  # over it
    "10 1 1 1 EW",
    "10 state sometimes",
]


def fap_mask(faps):
    return " ".join("1" if i in faps else "0" for i in range(1, 69))


def fap_file(frames, faps, values, header="2.1 synthetic 25", end="\n"):
    """A synthetic MPEG-4 FAP file (fuzz_fap_file's seeds; never the real shared ones)."""
    lines = [f"{header} {frames}"]
    for k in range(frames):
        lines += [fap_mask(faps), f"{k} " + " ".join(values(k))]
    return (end.join(lines) + end).encode()


# Synthetic FAP files: plain, with comments and CRLF, fractions, visemes and expressions,
# more than 40 FAPs at once, and bad ones (truncated, mask of 67, value out of range).
FAP_FILES = {
    "plain": fap_file(5, {3, 4, 48}, lambda k: [str(10 * k), str(-k), "0"]),
    "crlf-comments": b"# a comment\r\n" + fap_file(2, {19, 20}, lambda k: ["1", "2"],
                                                     header="2.0 C:\\faces\\a b 12.5",
                                                     end="\r\n"),
    "fractions": fap_file(3, {5}, lambda k: [f"{k}.5"]),
    "viseme-expression": fap_file(3, {1, 2, 3}, lambda k: ["3", "4", "50", "1",
                                                          "1", "40", "6", str(k), "0", "0",
                                                          "-7"]),
    "all-faps": fap_file(2, set(range(3, 69)), lambda k: [str(i * (k + 1)) for i in range(3, 69)],
                         header="2.1 all 1000"),
    "truncated": fap_file(3, {3}, lambda k: [str(k)])[:-3],
    "mask-67": b"2.1 t 25 1\n" + fap_mask({3})[:-2].encode() + b"\n0 1\n",
    "out-of-range": fap_file(1, {3}, lambda k: ["2529601"]),
    "absurd-count": b"2.1 t 25 99999999999\n",
}


def write(harness, name, data):
    out = FUZZ / "corpus" / harness
    out.mkdir(parents=True, exist_ok=True)
    safe = re.sub(r"[^A-Za-z0-9_.-]", "_", name)
    (out / safe).write_bytes(data)


def hex_bytes(text):
    return bytes(int(b, 16) for b in text.split())


def sample_payloads():
    lines = (ROOT / "samples" / "hello.pfap-hex").read_text().splitlines()
    return [hex_bytes(l) for l in lines if l.strip() and not l.startswith("#")]


def rtp_input(packets):
    """fuzz_depay's input: per packet a 2-byte length, a control byte and the payload."""
    out = bytearray()
    for control, payload in packets:
        n = len(payload) + 1
        out += bytes([n >> 8, n & 0xFF, control]) + payload
    return bytes(out)


def main():
    for harness in ("fuzz_payload", "fuzz_bookmark", "fuzz_text", "fuzz_depay", "fuzz_fap_file",
                    "fuzz_marks"):
        shutil.rmtree(FUZZ / "corpus" / harness, ignore_errors=True)

    samples = sample_payloads()
    for name, text in VECTORS.items():
        write("fuzz_payload", "vector-" + name, hex_bytes(text))
    for name, text in BAD.items():
        write("fuzz_payload", "bad-" + name, hex_bytes(text))
    for i, payload in enumerate(samples, 1):
        write("fuzz_payload", f"hello-{i}", payload)

    examples = sorted((ROOT / "docs" / "examples").glob("*.pfap"))
    bookmarks = list(BOOKMARKS)
    for path in examples:
        for line in path.read_text().splitlines():
            found = re.findall(r"<FAP[^>]*>", line)
            if found:
                bookmarks.append("".join(found))
    for text in dict.fromkeys(bookmarks):  # unique, in order
        write("fuzz_bookmark", hashlib.sha1(text.encode()).hexdigest()[:12], text.encode())

    for path in examples:
        write("fuzz_text", path.stem, path.read_bytes())
    for i, line in enumerate(TEXT_LINES, 1):
        write("fuzz_text", f"line-{i}", line.encode())

    # Control bytes: the marker (0x01) on each sentence's first packet, the next seqnum
    # (0x00), then variations: two lost (0x20: forward by 3), the other SSRC (0x02), a flush
    # (0x04), a packet-lost event (0x08), a seqnum going far back (0x0C), and bad payloads
    # among good ones.
    vectors = [hex_bytes(t) for t in VECTORS.values()]
    write("fuzz_depay", "hello", rtp_input([(0x01, samples[0]), (0x00, samples[1]),
                                            (0x00, samples[2]), (0x00, samples[3])]))
    write("fuzz_depay", "hello-loss", rtp_input([(0x01, samples[0]), (0x20, samples[1]),
                                                 (0x00, samples[2])]))
    write("fuzz_depay", "hello-events", rtp_input([(0x01, samples[2]), (0x08, samples[0]),
                                                   (0x04, samples[1]), (0x0C, samples[2]),
                                                   (0x03, samples[0])]))
    write("fuzz_depay", "vectors", rtp_input([(0x00, v) for v in vectors]))
    write("fuzz_depay", "bad", rtp_input([(0x00, hex_bytes(t)) for t in BAD.values()] +
                                         [(0x00, b"")]))
    write("fuzz_depay", "mixed", rtp_input([(0x01, samples[0]), (0x00, hex_bytes(BAD["curve_zero"])),
                                            (0x20, samples[1]), (0x00, samples[2])]))

    for name, data in FAP_FILES.items():
        write("fuzz_fap_file", name, data)
    # fuzz_marks: a format byte (0 Polly, 1 Rhubarb lines, 2 Rhubarb JSON, 3 Azure), then the
    # example files of docs/examples/marks/.
    marks = ROOT / "docs" / "examples" / "marks"
    for mode, name in ((0, "hello.polly.jsonl"), (1, "hello.rhubarb.tsv"),
                       (2, "hello.rhubarb.json"), (3, "hello.azure.jsonl")):
        write("fuzz_marks", name, bytes([mode]) + (marks / name).read_bytes())
    write("fuzz_marks", "azure-spellings", b"\x03" + b"""{"AudioOffset":500000,"VisemeId":0}
{"audio_offset":1004999,"viseme_id":21}
{"audioOffset":1e7,"visemeId":2}
""")
    write("fuzz_marks", "polly-escapes", b"\x00" + b"""{"time":0,"type":"sentence","value":"a\\u00e9\\ud83d\\ude00"}
{"time":1,"type":"word","value":"x"}
{"time":1,"type":"viseme","value":"p"}
{"time":99999999999999999,"type":"viseme","value":"sil"}
""")


if __name__ == "__main__":
    main()
