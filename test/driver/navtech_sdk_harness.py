"""Runs Navtech's SDK example ReadOneRotationOfFFTData.py, unchanged, against HOST:PORT.

The example hard-codes tcp_ip 192.168.0.1 and uses two names it never defines (client_socket,
where radar_socket is meant, and write_to_log): this harness supplies them and redirects the
connection, without editing the script. It also counts, from the bytes the example received,
which FFT messages arrived, and checks the rotation the example assembled.
Usage: python3 navtech_sdk_harness.py EXAMPLE.py HOST PORT  (exit 0: a full rotation read)
"""
import socket
import sys
import time

import numpy as np

example, host, port = sys.argv[1], sys.argv[2], int(sys.argv[3])
SIGNATURE = bytes([0x00, 0x01, 0x03, 0x03, 0x07, 0x07, 0x0F, 0x0F,
                   0x1F, 0x1F, 0x3F, 0x3F, 0x7F, 0x7F, 0xFE, 0xFE])
namespace = {"__name__": "__main__", "__file__": example}
wire = {"buf": bytearray(), "types": {}, "encoders": set(), "versions": set(), "zero_rows": set()}
assembled = []


def write_to_log(message, *args):
    print("example log: {}".format(message))


class RedirectedSocket(socket.socket):
    def connect(self, address):
        print("harness: example connects to {}:{}, redirected to {}:{}".format(
            address[0], address[1], host, port))
        super().connect((host, port))
        namespace["client_socket"] = self  # the name the example reads from

    def send(self, data, *args):
        print("harness: example sends {}".format(data.hex(" ")))
        return super().send(data, *args)

    def recv(self, n, *args):
        data = super().recv(n, *args)
        count_messages(data)
        return data


def count_messages(data):
    buf = wire["buf"]
    buf += data
    while len(buf) >= 22:
        start = buf.find(SIGNATURE)
        if start < 0:
            del buf[:-15]
            return
        del buf[:start]
        if len(buf) < 22:
            return
        size = int.from_bytes(buf[18:22], "big")
        if len(buf) < 22 + size:
            return
        mtype = buf[17]
        wire["versions"].add(buf[16])
        wire["types"][mtype] = wire["types"].get(mtype, 0) + 1
        if mtype in (30, 31) and size >= 14:
            encoder = int.from_bytes(buf[26:28], "big")
            wire["encoders"].add(encoder)
            if not any(buf[22 + 14:22 + size]):
                wire["zero_rows"].add(encoder)
        del buf[:22 + size]


original_interp = np.interp


def recording_interp(x, *args, **kwargs):
    if not assembled:
        assembled.append(np.array(x))  # the example's rotation, before it scales it
    return original_interp(x, *args, **kwargs)


socket.socket = RedirectedSocket
np.interp = recording_interp
namespace["write_to_log"] = write_to_log
t0 = time.time()
try:
    exec(compile(open(example).read(), example, "exec"), namespace)
except SystemExit:
    print("harness: the example exited early")
elapsed = time.time() - t0

samples = namespace.get("azimuth_samples", 0)
captured = namespace.get("fft_data_captured", 0)
rows = int(np.count_nonzero(assembled[0][:, :, 1].any(axis=1))) if assembled else 0
print("harness: on the wire: {} configuration, {} FFT messages ({} distinct azimuths), "
      "{} keep-alives, protocol version byte(s) {}".format(
          wire["types"].get(10, 0), wire["types"].get(30, 0) + wire["types"].get(31, 0),
          len(wire["encoders"]), wire["types"].get(1, 0), sorted(wire["versions"])))
print("harness: rows all zero on the wire: {}".format(len(wire["zero_rows"])))
print("harness: the example read {} FFT messages; its rotation has {} of {} azimuth rows "
      "with data; {:.1f} s in all".format(captured, rows, samples, elapsed))
if samples > 0 and rows == samples and len(wire["encoders"]) >= samples:
    print("harness: full rotation received")
    sys.exit(0)
print("harness: FAILED: no full rotation")
sys.exit(1)
