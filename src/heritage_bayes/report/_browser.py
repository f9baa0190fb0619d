"""Open a local HTML file in headless Chromium and record what happened.

Dependency-free: Chromium's DevTools protocol over ``--remote-debugging-pipe`` (JSON
messages separated by NUL bytes on file descriptors 3 and 4, the transport Playwright
and Puppeteer use), so no websocket client and no browser download is needed — only
Debian's ``chromium`` package (or the executable named by ``HB_CHROMIUM``).

:func:`open_page` loads the file, waits for the load event, and returns the console
messages, uncaught exceptions, browser log entries (CSP violations, failed loads), every
network request the page made, the result of a few DOM queries and a PNG screenshot.
:func:`screenshot_figure` embeds a page's first screen in the manual (the docs build);
the browser tests (``tests/_browser_checks.py``) check pages with :func:`open_page`.
"""

from __future__ import annotations

import base64
import fcntl
import json
import os
import select
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

__all__ = [
    "BROKEN_WORDS",
    "PHONE_OVERFLOW_JS",
    "PageResult",
    "find_chromium",
    "open_page",
    "screenshot_figure",
]

_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--no-default-browser-check",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-extensions",
    "--disable-default-apps",
    "--disable-dev-shm-usage",
    "--hide-scrollbars",
    "--mute-audio",
    "--remote-debugging-pipe",
]


#: A JavaScript expression: the words of the table cells that a line break cuts in two
#: (a number, an interval's bound, "conservatio|n"); breaks at a hyphen, a soft hyphen,
#: a slash or a semicolon are a word's own and are not counted.
BROKEN_WORDS = r"""(() => {
  const broken = [];
  for (const td of document.querySelectorAll('td, th')) {
    const walker = document.createTreeWalker(td, NodeFilter.SHOW_TEXT);
    let n;
    while ((n = walker.nextNode())) {
      const re = /[^\s\-\u00ad/;]+/g;
      let m;
      while ((m = re.exec(n.data))) {
        const r = document.createRange();
        r.setStart(n, m.index);
        r.setEnd(n, m.index + m[0].length);
        let rects = [...r.getClientRects()].filter(x => x.width >= 1);
        // Chromium draws the hyphen of a soft-hyphen break as part of the next word
        if (m.index > 0 && n.data[m.index - 1] === '\u00ad') rects = rects.slice(1);
        const tops = new Set(rects.map(x => Math.round(x.top)));
        if (tops.size > 1) broken.push(m[0]);
      }
    }
  }
  return broken.slice(0, 20);
})()"""

#: What sticks out of a phone's screen (390 px) outside the sideways-scrolling tables
#: and code, and the broken words of :data:`BROKEN_WORDS`: ``extra_js`` for
#: :func:`open_page`.
PHONE_OVERFLOW_JS = (
    """(() => {
  const W = document.documentElement.clientWidth, wide = [];
  for (const e of document.querySelectorAll('body *')) {
    if (e.closest('.scroll') || e.closest('pre')) continue;
    const r = e.getBoundingClientRect();
    if (r.right > W + 1) wide.push(e.tagName + ': ' + (e.textContent || '').slice(0, 60));
  }
  return {W: W, docw: document.documentElement.scrollWidth, wide: wide.slice(0, 10),
          broken: """
    + BROKEN_WORDS
    + """};
})()"""
)


def find_chromium() -> str | None:
    """Path of a Chromium/Chrome executable, or None."""
    env = os.environ.get("HB_CHROMIUM")
    if env and Path(env).is_file():
        return env
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


@dataclass
class PageResult:
    console: list[dict] = field(default_factory=list)  # Runtime.consoleAPICalled
    exceptions: list[dict] = field(default_factory=list)  # Runtime.exceptionThrown
    log: list[dict] = field(default_factory=list)  # Log.entryAdded
    requests: list[str] = field(default_factory=list)  # URLs of Network.requestWillBeSent
    dom: dict = field(default_factory=dict)
    screenshot: bytes = b""

    @property
    def errors(self) -> list[str]:
        """Console errors, uncaught exceptions and error/warning log entries, as text."""
        out = [
            f"console.{m.get('type')}: {m.get('args')}"
            for m in self.console
            if m.get("type") in ("error", "assert", "warning")
        ]
        out += [f"exception: {e.get('exceptionDetails', {}).get('text')}" for e in self.exceptions]
        out += [
            f"log {e['entry'].get('level')}: {e['entry'].get('text')} ({e['entry'].get('url', '')})"
            for e in self.log
            if e.get("entry", {}).get("level") in ("error", "warning")
        ]
        return out


class _Pipe:
    def __init__(self, write_fd: int, read_fd: int, proc: subprocess.Popen):
        self.w, self.r, self.proc = write_fd, read_fd, proc
        self.buf = b""
        self.next_id = 0
        self.events: list[dict] = []

    def send(
        self,
        method: str,
        params: dict | None = None,
        session: str | None = None,
        timeout: float = 30.0,
    ) -> dict:
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self.w, json.dumps(msg).encode() + b"\0")
        want = self.next_id
        deadline = time.monotonic() + timeout
        while True:
            m = self._read(deadline)
            if m.get("id") == want:
                if "error" in m:
                    raise RuntimeError(f"{method}: {m['error']}")
                return m.get("result", {})
            self.events.append(m)

    def wait_event(self, method: str, timeout: float = 30.0) -> dict:
        for i, m in enumerate(self.events):
            if m.get("method") == method:
                return self.events.pop(i)
        deadline = time.monotonic() + timeout
        while True:
            m = self._read(deadline)
            if m.get("method") == method:
                return m
            self.events.append(m)

    def drain(self, seconds: float) -> None:
        deadline = time.monotonic() + seconds
        while True:
            try:
                self.events.append(self._read(deadline))
            except TimeoutError:
                return

    def _read(self, deadline: float) -> dict:
        while b"\0" not in self.buf:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError("no answer from Chromium")
            ready, _, _ = select.select([self.r], [], [], left)
            if not ready:
                continue
            chunk = os.read(self.r, 1 << 20)
            if not chunk:
                raise RuntimeError(f"Chromium closed the pipe (exit code {self.proc.poll()})")
            self.buf += chunk
        raw, self.buf = self.buf.split(b"\0", 1)
        return json.loads(raw)


_DOM_QUERY = """JSON.stringify({
  sections: [...document.querySelectorAll('section[id]')].map(s => s.id),
  figures: [...document.querySelectorAll('figure[id]')].map(f => f.id),
  images: [...document.images].map(i => ({src: i.currentSrc.slice(0, 30), w: i.naturalWidth,
                                           h: i.naturalHeight, complete: i.complete})),
  scripts: document.scripts.length,
  title: document.title,
  verdict: (() => { const v = document.getElementById('verdict');
    if (!v) return null; const r = v.getBoundingClientRect();
    return {cls: v.className, top: r.top, height: r.height, text: v.innerText}; })(),
  bodyText: document.body.innerText.length,
  height: document.documentElement.scrollHeight,
})"""


def open_page(
    path: str | Path,
    *,
    chromium: str | None = None,
    width: int = 1280,
    height: int = 1600,
    timeout: float = 60.0,
    extra_js: str | None = None,
) -> PageResult:
    """Load ``path`` (a local file) in headless Chromium; see the module docstring.

    ``extra_js`` is evaluated after load and its (JSON-serialisable) value stored in
    ``result.dom["extra"]``.
    """
    exe = chromium or find_chromium()
    if exe is None:
        raise FileNotFoundError("chromium not found")
    url = Path(path).resolve().as_uri()
    profile = tempfile.mkdtemp(prefix="hb-chromium-")
    # the child's ends are moved above fd 9 first, so that dup2 onto 3 and 4 in the
    # child cannot clobber one with the other
    r, to_child_w = os.pipe()
    to_child_r = fcntl.fcntl(r, fcntl.F_DUPFD_CLOEXEC, 10)
    os.close(r)
    from_child_r, w = os.pipe()
    from_child_w = fcntl.fcntl(w, fcntl.F_DUPFD_CLOEXEC, 10)
    os.close(w)

    def _child_fds():  # in the child, before exec: commands on fd 3, answers on fd 4
        os.dup2(to_child_r, 3)
        os.dup2(from_child_w, 4)

    proc = subprocess.Popen(
        [
            exe,
            *_FLAGS,
            f"--user-data-dir={profile}",
            f"--window-size={width},{height}",
            "about:blank",
        ],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        close_fds=False,
        preexec_fn=_child_fds,
    )
    os.close(to_child_r)
    os.close(from_child_w)
    pipe = _Pipe(to_child_w, from_child_r, proc)
    res = PageResult()
    try:
        target = pipe.send("Target.createTarget", {"url": "about:blank"}, timeout=timeout)
        sid = pipe.send("Target.attachToTarget", {"targetId": target["targetId"], "flatten": True})[
            "sessionId"
        ]
        for domain in ("Runtime", "Log", "Network", "Page"):
            pipe.send(f"{domain}.enable", session=sid)
        pipe.send(
            "Emulation.setDeviceMetricsOverride",
            {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
            session=sid,
        )
        pipe.events.clear()  # about:blank's own events
        pipe.send("Page.navigate", {"url": url}, session=sid, timeout=timeout)
        pipe.wait_event("Page.loadEventFired", timeout=timeout)
        pipe.drain(0.5)  # late console/log events
        value = pipe.send(
            "Runtime.evaluate", {"expression": _DOM_QUERY, "returnByValue": True}, session=sid
        )["result"]["value"]
        res.dom = json.loads(value)
        if extra_js:
            res.dom["extra"] = pipe.send(
                "Runtime.evaluate", {"expression": extra_js, "returnByValue": True}, session=sid
            )["result"].get("value")
        shot = pipe.send("Page.captureScreenshot", {"format": "png"}, session=sid, timeout=timeout)
        res.screenshot = base64.b64decode(shot["data"])
        pipe.drain(0.2)
        for ev in pipe.events:
            method, params = ev.get("method"), ev.get("params", {})
            if method == "Runtime.consoleAPICalled":
                res.console.append(
                    {
                        "type": params.get("type"),
                        "args": [
                            a.get("value", a.get("description")) for a in params.get("args", [])
                        ],
                    }
                )
            elif method == "Runtime.exceptionThrown":
                res.exceptions.append(params)
            elif method == "Log.entryAdded":
                res.log.append(params)
            elif method == "Network.requestWillBeSent":
                res.requests.append(params.get("request", {}).get("url", ""))
        try:
            pipe.send("Browser.close", timeout=5)
        except (RuntimeError, TimeoutError, OSError):
            pass
    finally:
        os.close(to_child_w)
        os.close(from_child_r)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=10)
        shutil.rmtree(profile, ignore_errors=True)
    return res


def screenshot_figure(
    path: str | Path,
    caption: str,
    *,
    section: str | None = None,
    width: int = 1280,
    height: int = 800,
) -> str:
    """HTML of a ``<figure>``: the first screen of the page ``path`` (scrolled to the
    element with id ``section``, if given) at ``width`` × ``height`` px, a PNG embedded
    as a data URI, for the manual's build. Without Chromium: a visible placeholder
    saying that the screenshot needs it, and a note on stderr (the build log) — never
    a silent gap."""
    import html
    import sys

    name = Path(path).name + (f"#{section}" if section else "")
    if find_chromium() is None:
        print(f"docs: chromium not found: the screenshot of {name} needs it", file=sys.stderr)
        return (
            f'<div class="admonition note"><p class="admonition-title">Screenshot of '
            f"{html.escape(name)} not built</p><p>This screenshot is taken with headless "
            "Chromium (the <code>chromium</code> package) when the site is built; the "
            "machine that built this site did not have it. The page itself is "
            f"<code>{html.escape(str(path))}</code>.</p></div>"
        )
    scroll = None
    if section:
        scroll = (
            f"(() => {{ const e = document.getElementById({json.dumps(section)}); "
            "if (!e) return null; e.scrollIntoView(); return window.scrollY; })()"
        )
    shot = open_page(path, width=width, height=height, extra_js=scroll)
    if section and shot.dom.get("extra") is None:
        raise ValueError(f"{path}: no element with id {section!r} to scroll to")
    data = base64.b64encode(shot.screenshot).decode("ascii")
    return (
        f'<figure><img src="data:image/png;base64,{data}" width="{width}" '
        f'alt="first screen of {html.escape(name)}" style="border:1px solid #ccc">'
        f"<figcaption>{html.escape(caption)}</figcaption></figure>"
    )
