#include "pipeline/watch/watch_server.h"

#include <httplib.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "base/json_number.h"
#include "base/user_error.h"

namespace bifilar {

struct WatchServer::State {
  httplib::Server server;
  std::thread thread;
  int port = 0;
  std::mutex mutex;
  std::condition_variable changed;
  long sequence = 0;
  bool stopping = false;
  std::string message = "{}";                        // the last message sent
  nlohmann::json history = nlohmann::json::array();  // [cycles, I, std stat] of this swing
  int swing = 0;
  nlohmann::json events = nlohmann::json::array();  // the last few lines of news

  void Send() {  // with `mutex` held
    message = nlohmann::json{{"history", history}, {"events", events}, {"update", last}}.dump();
    ++sequence;
    changed.notify_all();
  }
  nlohmann::json last = nlohmann::json::object();
};

namespace {

constexpr size_t kMaxHistory = 4000;
constexpr size_t kMaxEvents = 8;

}  // namespace

WatchServer::WatchServer(int port) : state_(std::make_unique<State>()) {
  State* s = state_.get();
  s->server.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(WatchPageHtml(), "text/html; charset=utf-8");
  });
  s->server.Get("/state", [s](const httplib::Request&, httplib::Response& res) {
    std::lock_guard<std::mutex> lock(s->mutex);
    res.set_content(s->message, "application/json");
  });
  s->server.Get("/events", [s](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-cache");
    long seen = -1;  // the current state goes out at once
    res.set_chunked_content_provider(
        "text/event-stream", [s, seen](size_t, httplib::DataSink& sink) mutable {
          std::unique_lock<std::mutex> lock(s->mutex);
          s->changed.wait_for(lock, std::chrono::seconds(1),
                              [&] { return s->sequence != seen || s->stopping; });
          if (s->stopping) {
            sink.done();
            return false;
          }
          std::string text = ": keep-alive\n\n";
          if (s->sequence != seen) {
            seen = s->sequence;
            text = "data: " + s->message + "\n\n";
          }
          lock.unlock();
          return sink.write(text.data(), text.size());
        });
  });
  if (port == 0) {
    s->port = s->server.bind_to_any_port("127.0.0.1");
  } else {
    s->port = s->server.bind_to_port("127.0.0.1", port) ? port : -1;
  }
  if (s->port <= 0) {
    throw UserError("watch --serve: cannot listen on 127.0.0.1:" + std::to_string(port) +
                    " (in use? give another port, or 0 for any free one)");
  }
  s->thread = std::thread([s] { s->server.listen_after_bind(); });
}

WatchServer::~WatchServer() {
  {
    std::lock_guard<std::mutex> lock(state_->mutex);
    state_->stopping = true;
    state_->changed.notify_all();
  }
  state_->server.stop();
  if (state_->thread.joinable()) state_->thread.join();
}

int WatchServer::port() const { return state_->port; }

std::string WatchServer::url() const {
  return "http://127.0.0.1:" + std::to_string(state_->port) + "/";
}

void WatchServer::Publish(const WatchUpdate& update) {
  std::lock_guard<std::mutex> lock(state_->mutex);
  State& s = *state_;
  if (update.swing != s.swing) {
    s.history = nlohmann::json::array();
    s.swing = update.swing;
  }
  if (update.verdict != WatchVerdict::kWaiting && std::isfinite(update.inertia_kg_m2) &&
      s.history.size() < kMaxHistory) {
    s.history.push_back({JsonNumber(update.cycles), JsonNumber(update.inertia_kg_m2),
                         JsonNumber(update.inertia_std_stat_kg_m2)});
  }
  s.last = WatchUpdateToJson(update);
  s.Send();
}

void WatchServer::Event(const std::string& text) {
  std::lock_guard<std::mutex> lock(state_->mutex);
  state_->events.push_back(text);
  if (state_->events.size() > kMaxEvents) state_->events.erase(state_->events.begin());
  state_->Send();
}

std::string WatchPageHtml() {
  return R"HTML(<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>bifilar watch</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>
body{font-family:system-ui,sans-serif;margin:1.5em;background:#fafafa;color:#222}
#verdict{font-size:5em;font-weight:bold;margin:.1em 0}
.waiting{color:#777}.swinging{color:#1f5fa8}.enough{color:#1b7f2a}.swing_again{color:#b36b00}.fix_rig{color:#b00020}
#reason{font-size:1.4em;margin-bottom:1em}
table{border-collapse:collapse;font-size:1.3em}td{padding:.15em .8em}td.v{font-variant-numeric:tabular-nums;font-weight:600}
svg{background:#fff;border:1px solid #ccc;margin-top:1em}
#events{color:#555;margin-top:1em;font-size:.95em}
</style></head><body>
<div id="verdict" class="waiting">WAITING</div>
<div id="reason">connecting ...</div>
<table>
<tr><td>time</td><td class="v" id="t">-</td><td>IMU rate</td><td class="v" id="rate">-</td></tr>
<tr><td>swing</td><td class="v" id="swing">-</td><td>rate noise</td><td class="v" id="noise">-</td></tr>
<tr><td>cycles</td><td class="v" id="cycles">-</td><td>amplitude</td><td class="v" id="amplitude">-</td></tr>
<tr><td>period</td><td class="v" id="period">-</td><td>I (small-angle)</td><td class="v" id="small">-</td></tr>
<tr><td>I (full model)</td><td class="v" id="inertia">-</td><td>std stat / total</td><td class="v" id="std">-</td></tr>
<tr><td>cycles still needed</td><td class="v" id="needed">-</td><td>repeats</td><td class="v" id="repeat">-</td></tr>
<tr><td>updates</td><td class="v" id="updates" data-first-t="">0</td><td></td><td></td></tr>
</table>
<svg id="plot" width="720" height="300" viewBox="0 0 720 300" role="img" aria-label="I against cycles">
<polygon id="band" fill="#1f5fa8" fill-opacity="0.2" points=""></polygon>
<polyline id="line" fill="none" stroke="#1f5fa8" stroke-width="2" points=""></polyline>
<text x="8" y="16" font-size="13">I (kg m^2) against cycles, band: +-1 std</text>
<text id="ymax" x="8" y="36" font-size="12"></text><text id="ymin" x="8" y="292" font-size="12"></text>
<text id="xmax" x="680" y="292" font-size="12"></text>
</svg>
<div id="events"></div>
<script>
"use strict";
function num(v, digits) { return (v === null || v === undefined) ? "-" : Number(v).toPrecision(digits); }
function set(id, text) { document.getElementById(id).textContent = text; }
let updates = 0;
function draw(history) {
  const line = document.getElementById("line"), band = document.getElementById("band");
  if (history.length === 0) { line.setAttribute("points", ""); band.setAttribute("points", ""); return; }
  let lo = Infinity, hi = -Infinity, cmax = 0;
  for (const [c, i, s] of history) { lo = Math.min(lo, i - s); hi = Math.max(hi, i + s); cmax = Math.max(cmax, c); }
  if (!(hi > lo)) { hi = lo + 1e-12; }
  const pad = 0.05 * (hi - lo); lo -= pad; hi += pad; cmax = Math.max(cmax, 1);
  const x = c => 60 + 640 * c / cmax, y = v => 280 - 260 * (v - lo) / (hi - lo);
  line.setAttribute("points", history.map(([c, i]) => x(c) + "," + y(i)).join(" "));
  const upper = history.map(([c, i, s]) => x(c) + "," + y(i + s));
  const lower = history.slice().reverse().map(([c, i, s]) => x(c) + "," + y(i - s));
  band.setAttribute("points", upper.concat(lower).join(" "));
  set("ymax", hi.toPrecision(6)); set("ymin", lo.toPrecision(6)); set("xmax", cmax.toFixed(1));
}
function show(message) {
  const u = message.update || {};
  if (u.verdict) {
    const v = document.getElementById("verdict");
    v.className = u.verdict; v.textContent = u.verdict.replace("_", " ").toUpperCase();
    set("reason", u.reason || "");
    set("t", num(u.t_s, 6) + " s"); set("rate", num(u.rate_hz, 4) + " Hz");
    set("noise", num(u.rate_noise_rad_per_s, 2) + " rad/s"); set("swing", String(u.swing));
    set("cycles", num(u.cycles, 3)); set("amplitude", num(u.amplitude_deg, 3) + " deg");
    set("period", num(u.period_s, 6) + " s"); set("small", num(u.small_angle_inertia_kg_m2, 6) + " kg m^2");
    set("inertia", num(u.inertia_kg_m2, 7) + " kg m^2");
    set("std", num(u.inertia_std_stat_kg_m2, 2) + " / " + num(u.inertia_std_total_kg_m2, 2));
    set("needed", num(u.cycles_needed, 2)); set("repeat", u.repeat_agreement || "-");
    updates += 1;
    const counter = document.getElementById("updates");
    if (counter.dataset.firstT === "") { counter.dataset.firstT = String(u.t_s); }
    counter.textContent = String(updates);
  }
  draw(message.history || []);
  set("events", (message.events || []).join("\n"));
}
const source = new EventSource("/events");
source.onmessage = e => show(JSON.parse(e.data));
source.onerror = () => set("reason", "the watch has ended or the connection was lost");
</script></body></html>
)HTML";
}

}  // namespace bifilar
