"""A small INDI client (the XML protocol over TCP) for the end-to-end test.

Keeps the last value and state of every property and the driver's messages;
new*Vector sends a client change.  Standard library only.
"""
import socket
import threading
import time
import xml.etree.ElementTree as ET


class IndiError(Exception):
    pass


class Client:
    def __init__(self, host, port, timeout=10.0):
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.sock.settimeout(None)
        self.lock = threading.Condition()
        self.props = {}        # (device, name) -> {"state": s, "values": {elem: text}, "kind": k}
        self.messages = []     # (time, device, text)
        self.closed = False
        self.parser = ET.XMLPullParser(events=("end",))
        self.parser.feed("<stream>")
        self.depth_elems = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()
        self.send('<getProperties version="1.7"/>')

    def send(self, text):
        self.sock.sendall(text.encode() + b"\n")

    def close(self):
        self.closed = True
        try:
            self.sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self.sock.close()

    def _read(self):
        while not self.closed:
            try:
                data = self.sock.recv(65536)
            except OSError:
                break
            if not data:
                break
            try:
                self.parser.feed(data.decode("utf-8", "replace"))
                for _, el in self.parser.read_events():
                    self._handle(el)
            except ET.ParseError as e:
                with self.lock:
                    self.messages.append((time.time(), "", "client: XML parse error %s" % e))
                break
        with self.lock:
            self.closed = True
            self.lock.notify_all()

    def _handle(self, el):
        tag = el.tag
        if tag == "message":
            with self.lock:
                self.messages.append((time.time(), el.get("device", ""), el.get("message", "")))
                self.lock.notify_all()
            el.clear()
            return
        if not (tag.startswith("def") or tag.startswith("set")) or not tag.endswith("Vector"):
            return
        dev, name = el.get("device"), el.get("name")
        with self.lock:
            p = self.props.setdefault((dev, name), {"state": None, "values": {}, "kind": tag[3:]})
            if el.get("state"):
                p["state"] = el.get("state")
            for child in el:
                p["values"][child.get("name")] = (child.text or "").strip()
            p["time"] = time.time()
            if el.get("message"):
                self.messages.append((time.time(), dev, el.get("message")))
            self.lock.notify_all()
        el.clear()

    # -- queries --------------------------------------------------------
    def wait(self, pred, timeout, what):
        end = time.time() + timeout
        with self.lock:
            while True:
                r = pred()
                if r:
                    return r
                left = end - time.time()
                if left <= 0 or self.closed:
                    raise IndiError("timed out after %.0f s waiting for %s" % (timeout, what))
                self.lock.wait(min(left, 0.5))

    def prop(self, dev, name):
        with self.lock:
            p = self.props.get((dev, name))
            return None if p is None else {"state": p["state"], "values": dict(p["values"]),
                                           "time": p.get("time", 0)}

    def wait_prop(self, dev, name, timeout=10):
        return self.wait(lambda: self.props.get((dev, name)), timeout, "%s.%s" % (dev, name))

    def number(self, dev, name, elem):
        p = self.prop(dev, name)
        if p is None or elem not in p["values"]:
            raise IndiError("no %s.%s.%s" % (dev, name, elem))
        return float(p["values"][elem])

    # -- changes ----------------------------------------------------------
    def set_switch(self, dev, name, on, off=()):
        items = "".join('<oneSwitch name="%s">On</oneSwitch>' % x for x in on)
        items += "".join('<oneSwitch name="%s">Off</oneSwitch>' % x for x in off)
        self.send('<newSwitchVector device="%s" name="%s">%s</newSwitchVector>' % (dev, name, items))

    def set_number(self, dev, name, values):
        items = "".join('<oneNumber name="%s">%.17g</oneNumber>' % (k, v) for k, v in values.items())
        self.send('<newNumberVector device="%s" name="%s">%s</newNumberVector>' % (dev, name, items))

    def set_text(self, dev, name, values):
        items = "".join('<oneText name="%s">%s</oneText>' % (k, v) for k, v in values.items())
        self.send('<newTextVector device="%s" name="%s">%s</newTextVector>' % (dev, name, items))
