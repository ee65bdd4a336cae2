#include "status_page.hpp"

namespace horus::tools::fox {

namespace {

constexpr std::string_view kPage = R"HTML(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>horus fleet</title>
<style>
  body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #1d2330; background: #f6f7f9; }
  h1 { font-size: 1.4em; margin: 0 0 .2em; }
  h2 { font-size: 1.1em; margin: 1.4em 0 .4em; }
  .sub { color: #5b6475; }
  table { border-collapse: collapse; background: #fff; min-width: 40em; box-shadow: 0 1px 2px #0002; }
  th, td { padding: .35em .8em; text-align: left; border-bottom: 1px solid #e4e7ec; white-space: nowrap; }
  th { background: #eef1f5; font-weight: 600; }
  td.num { text-align: right; font-variant-numeric: tabular-nums; }
  .alive, .this { color: #137333; font-weight: 600; }
  .lost { color: #b3261e; font-weight: 600; }
  .rejoined { color: #a15c00; font-weight: 600; }
  #error { color: #b3261e; }
</style>
</head>
<body>
<h1>horus fleet</h1>
<div class="sub">served by <b id="server">…</b> on <span id="where">…</span>; updated <span id="updated">never</span> <span id="error"></span></div>
<h2>Hosts (<span id="nhosts">0</span>)</h2>
<table id="hosts"><thead><tr><th>host</th><th>state</th><th>heartbeat age</th><th>RTT</th><th>clock offset</th><th>loss</th><th>topics</th></tr></thead><tbody></tbody></table>
<h2>Topics (<span id="ntopics">0</span>)</h2>
<table id="topics"><thead><tr><th>topic</th><th>type</th><th>scope</th><th>hosts</th><th>rate</th><th>bandwidth</th><th>pub / sub</th><th>dropped</th></tr></thead><tbody></tbody></table>
<h2>Foxglove clients (<span id="nclients">0</span>)</h2>
<table id="clients"><thead><tr><th>client</th><th>subscriptions</th><th>messages sent</th><th>dropped (slow reader)</th><th>published</th></tr></thead><tbody></tbody></table>
<script>
"use strict";
function cell(row, text, cls) {
  const td = document.createElement("td");
  td.textContent = text;
  if (cls) td.className = cls;
  row.appendChild(td);
}
function fill(id, rows, make) {
  const body = document.querySelector("#" + id + " tbody");
  body.replaceChildren();
  for (const r of rows) { const tr = document.createElement("tr"); make(tr, r); body.appendChild(tr); }
}
function us(v) { return v === null || v === undefined ? "–" : (Math.abs(v) >= 1000 ? (v / 1000).toFixed(2) + " ms" : v + " µs"); }
function rate(v) { return v < 0 ? "–" : v.toFixed(1) + " Hz"; }
function bw(v) {
  if (v < 0) return "–";
  if (v >= 1e6) return (v / 1e6).toFixed(2) + " MB/s";
  if (v >= 1e3) return (v / 1e3).toFixed(1) + " kB/s";
  return v.toFixed(0) + " B/s";
}
async function refresh() {
  try {
    const s = await (await fetch("/status.json", {cache: "no-store"})).json();
    document.getElementById("server").textContent = s.server.host;
    document.getElementById("where").textContent = s.server.transport ? "the fleet (" + s.server.transport + ")" : "this host only";
    document.getElementById("updated").textContent = new Date(s.server.unix_ms).toLocaleTimeString();
    document.getElementById("error").textContent = "";
    document.getElementById("nhosts").textContent = s.hosts.length;
    fill("hosts", s.hosts, (tr, h) => {
      cell(tr, h.name);
      cell(tr, h.state, h.self ? "this" : h.state);
      cell(tr, h.self ? "–" : h.age_ms + " ms", "num");
      cell(tr, us(h.rtt_us), "num");
      cell(tr, us(h.clock_offset_us), "num");
      cell(tr, h.loss < 0 ? "–" : (100 * h.loss).toFixed(0) + " %", "num");
      cell(tr, h.topics, "num");
    });
    document.getElementById("ntopics").textContent = s.topics.length;
    fill("topics", s.topics, (tr, t) => {
      cell(tr, t.name); cell(tr, t.type); cell(tr, t.scope); cell(tr, t.hosts.join(", "));
      cell(tr, rate(t.rate_hz), "num"); cell(tr, bw(t.bandwidth_bps), "num");
      cell(tr, t.publishers + " / " + t.subscribers, "num"); cell(tr, t.dropped, "num");
    });
    document.getElementById("nclients").textContent = s.clients.length;
    fill("clients", s.clients, (tr, c) => {
      cell(tr, c.peer); cell(tr, c.subscriptions, "num"); cell(tr, c.sent, "num");
      cell(tr, c.dropped, "num"); cell(tr, c.published, "num");
    });
    document.body.dataset.ready = "1";
  } catch (e) {
    document.getElementById("error").textContent = "(the server does not answer: " + e + ")";
  }
}
refresh();
setInterval(refresh, 1000);
</script>
</body>
</html>
)HTML";

}  // namespace

std::string_view status_page_html() { return kPage; }

}  // namespace horus::tools::fox
