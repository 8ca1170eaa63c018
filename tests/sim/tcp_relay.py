#!/usr/bin/env python3
"""A TCP relay that records every byte between hosts and a device, for checking what an
eavesdropper on the network sees.  tcp_relay.py DEVICE_PORT PORT_FILE RECORD_FILE
Listens on a free loopback port (written to PORT_FILE), forwards each connection to
127.0.0.1:DEVICE_PORT and appends the bytes of both directions to RECORD_FILE."""
import socket
import sys
import threading

device_port, port_file, record_file = int(sys.argv[1]), sys.argv[2], sys.argv[3]
lock = threading.Lock()


def pump(src, dst):
    try:
        while True:
            data = src.recv(65536)
            if not data:
                break
            with lock, open(record_file, "ab") as record:
                record.write(data)
            dst.sendall(data)
    except OSError:
        pass
    for s in (src, dst):
        try:
            s.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass


listener = socket.socket()
listener.bind(("127.0.0.1", 0))
listener.listen(8)
with open(port_file, "w") as f:
    f.write(str(listener.getsockname()[1]))
while True:
    host, _ = listener.accept()
    device = socket.create_connection(("127.0.0.1", device_port))
    threading.Thread(target=pump, args=(host, device), daemon=True).start()
    threading.Thread(target=pump, args=(device, host), daemon=True).start()
