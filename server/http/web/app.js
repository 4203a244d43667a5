// skyfarm's web page, an operator's console: submit a render or a timelapse
// (from the form or as JSON), watch it converge, list renders and timelapses
// by name with a thumbnail, filter them by state, see what each asked for,
// duplicate or re-submit it, drain and resume workers.  Plain ES module, no
// dependencies; it talks only to this server's API (api/openapi.yaml):
//
//   POST /v1/renders, /v1/timelapses          the form (400 problems shown by field)
//   POST /v1/workers/{id}/drain, .../resume   the workers' Drain / Resume buttons
//   GET  /v1/renders/{id}/image.png?width=N   the list's thumbnails (done renders)
//   GET  /v1/renders/{id}/events              Server-Sent Events, read with fetch() so
//                                             that a bearer token can be sent
//   GET  /v1/renders/{id}[/image.png]         status, progressive image (409 until the
//                                             first pass is merged)
//   GET  /v1/renders, /v1/timelapses, /v1/workers   the lists, every kListRefreshMs
//   GET  /v1/timelapses/{id}[/frames/{n}.png]  timelapse status (polled) and frames: a
//                                             frame's render PNG once its render is done,
//                                             fetched again once the timelapse is done
//                                             (then exposed as the sequence is)
//   DELETE /v1/renders/{id}, /v1/timelapses/{id}   cancel
//
// Every request carries "Authorization: Bearer <token>" when a token was
// entered (kept in sessionStorage); images and downloads are fetched as
// blobs for the same reason.  The location hash (#render=ID, #timelapse=ID)
// names what is shown, so a reload shows it again.

const kListRefreshMs = 2000;
const kTimelapsePollMs = 1500;
const kStreamRetryMs = 1000;
// The server writes a preview for each fetch that finds new merged units:
// at most one fetch a second while a render runs (and one for the final image).
const kImageIntervalMs = 1000;
const kThumbnailFetches = 3;  // frame images fetched at once
const kListThumbnailWidth = 96;  // px, the render list's thumbnails
// quality.samples_per_pixel when only a target error or a time limit stops a
// render (api/render_request.h kMaxSamplesPerPixel): no cap worth showing.
const kUncappedSamples = 1048576;
const kTokenKey = "skyfarm-token";
const kSvgNs = "http://www.w3.org/2000/svg";
const kTerminal = new Set(["done", "failed", "cancelled"]);

const $ = (selector) => document.querySelector(selector);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

// --- API access -------------------------------------------------------------

function authHeaders() {
  const token = sessionStorage.getItem(kTokenKey);
  return token ? { Authorization: `Bearer ${token}` } : {};
}

// {status, ok, data}: data is the parsed JSON (a problem document on errors);
// status 0 when the server could not be reached.
async function api(path, { method = "GET", body, signal } = {}) {
  const headers = { Accept: "application/json", ...authHeaders() };
  if (body !== undefined) headers["Content-Type"] = "application/json";
  try {
    const res = await fetch(path, {
      method, headers, signal, cache: "no-store",
      body: body === undefined ? undefined : JSON.stringify(body),
    });
    const type = res.headers.get("Content-Type") || "";
    const data = type.includes("json") ? await res.json() : null;
    return { status: res.status, ok: res.ok, data };
  } catch (error) {
    if (error.name === "AbortError") throw error;
    return { status: 0, ok: false, data: { title: "The server cannot be reached", detail: String(error.message || error) } };
  }
}

// An object URL of the image at `url`, or {status} when there is none (yet).
async function fetchBlobUrl(url, signal) {
  try {
    const res = await fetch(url, { headers: authHeaders(), cache: "no-store", signal });
    if (!res.ok) return { status: res.status };
    return { status: res.status, url: URL.createObjectURL(await res.blob()) };
  } catch (error) {
    if (error.name === "AbortError") throw error;
    return { status: 0 };
  }
}

// Links to files (EXR, video, ...): plain links, fetched with the token when there is one.
function setDownload(link, href, filename) {
  link.href = href;
  link.dataset.filename = filename;
}

document.addEventListener("click", async (event) => {
  const link = event.target.closest("a.authed-download");
  if (!link || !sessionStorage.getItem(kTokenKey)) return;
  event.preventDefault();
  const blob = await fetchBlobUrl(link.href);
  if (!blob.url) return;
  const a = document.createElement("a");
  a.href = blob.url;
  a.download = link.dataset.filename || "";
  a.click();
  setTimeout(() => URL.revokeObjectURL(blob.url), 60000);
});

// --- Small helpers ----------------------------------------------------------

const percent = (x, digits = 0) => `${(100 * x).toFixed(digits)} %`;
const isNumber = (x) => typeof x === "number" && Number.isFinite(x);

function seconds(s) {
  if (!isNumber(s)) return "–";
  if (s < 60) return `${s.toFixed(s < 10 ? 1 : 0)} s`;
  const m = Math.floor(s / 60);
  return `${m} min ${Math.round(s - 60 * m)} s`;
}

function shortId(id) { return id.length > 14 ? `${id.slice(0, 12)}…` : id; }

// Samples per pixel as people count them: "12.5 of 64 spp"; a render that
// stops by a target error or a time limit alone has no cap, so it says that.
function samplesText(progress, request) {
  const done = progress?.samples_per_pixel;
  if (!isNumber(done)) return "";
  const doneText = `${+done.toFixed(1)}`;
  const target = progress.samples_per_pixel_target;
  const q = request?.quality || {};
  if (isNumber(target) && target < kUncappedSamples) return `${doneText} of ${target} spp`;
  const stops = [isNumber(q.target_relative_error) ? `to ${percent(q.target_relative_error, 1)} error` : "",
    isNumber(q.time_limit_s) ? `for at most ${seconds(q.time_limit_s)}` : ""].filter(Boolean);
  return `${doneText} spp` + (stops.length ? ` (${stops.join(", ")})` : "");
}

const degrees = (x, pos, neg) => `${Math.abs(x).toFixed(2)}° ${x < 0 ? neg : pos}`;

// "42.44° N, 76.48° W" from a request's location.
function placeText(request) {
  const l = request?.location;
  if (!l || !isNumber(l.latitude_deg) || !isNumber(l.longitude_deg)) return "";
  return `${degrees(l.latitude_deg, "N", "S")}, ${degrees(l.longitude_deg, "E", "W")}`;
}

// "2013-05-28 00:25 UTC" (canonical requests give the time in UTC), or the
// sun's angles when the request gave them.
function timeText(request) {
  const clock = (t) => t.replace(/(T\d\d:\d\d):00(?=[Z+-]|$)/, "$1").replace("T", " ").replace(/Z$/i, " UTC").replace(/([+-]\d\d:?\d\d)$/, " $1");
  if (typeof request?.time === "string") return clock(request.time);
  if (typeof request?.start === "string") return `${clock(request.start)} to ${clock(request.end || "")}`;
  const sun = request?.sun;
  if (sun && isNumber(sun.zenith_deg)) return `sun at zenith ${sun.zenith_deg}°, azimuth ${sun.azimuth_deg ?? 0}°`;
  return "";
}

function cameraText(request) {
  const c = request?.camera;
  return c ? `${c.projection} ${c.width}×${c.height}` : "";
}

// A render's or timelapse's title: its name, else what it shows.
function titleOf(item) {
  if (item.name) return item.name;
  const place = placeText(item.request), time = timeText(item.request);
  return place || time ? `Sky over ${[place, time].filter(Boolean).join(", ")}` : `Render ${shortId(item.id)}`;
}

// The request an item asked for, with its name (which the canonical request
// leaves out): what Duplicate and Re-submit send.
function requestOf(item) {
  if (!item?.request) return null;
  const body = structuredClone(item.request);
  if (item.name) body.name = item.name;
  return body;
}

function element(tag, props = {}, children = []) {
  const node = document.createElement(tag);
  Object.assign(node, props);
  for (const child of [].concat(children)) node.append(child);
  return node;
}

// Updates the children of `parent` (table rows, list items) to `items`
// (keyed by `key`), keeping existing elements (and the focus inside them)
// instead of rebuilding the list.
function syncRows(parent, items, key, build, update) {
  const existing = new Map([...parent.children].map((row) => [row.dataset.key, row]));
  items.forEach((item, i) => {
    let row = existing.get(key(item));
    if (row) existing.delete(key(item));
    else { row = build(item); row.dataset.key = key(item); }
    update(row, item);
    if (parent.children[i] !== row) parent.insertBefore(row, parent.children[i] || null);
  });
  for (const row of existing.values()) row.remove();
}

// --- Time: a clock time in a zone to ISO 8601 with an offset -----------------

// Offset of the IANA `zone` at the UTC instant `ms`, in minutes east.
function zoneOffsetMinutes(zone, ms) {
  const format = new Intl.DateTimeFormat("en-US", {
    timeZone: zone, hourCycle: "h23", year: "numeric", month: "2-digit", day: "2-digit",
    hour: "2-digit", minute: "2-digit", second: "2-digit",
  });
  const parts = Object.fromEntries(format.formatToParts(new Date(ms)).map((p) => [p.type, p.value]));
  const wall = Date.UTC(+parts.year, +parts.month - 1, +parts.day, +parts.hour, +parts.minute, +parts.second);
  return Math.round((wall - Math.floor(ms / 1000) * 1000) / 60000);
}

function formatOffset(minutes) {
  if (minutes === 0) return "Z";
  const sign = minutes < 0 ? "-" : "+";
  const m = Math.abs(minutes);
  return `${sign}${String(Math.floor(m / 60)).padStart(2, "0")}:${String(m % 60).padStart(2, "0")}`;
}

// "2013-05-27T09:30" + "America/New_York" -> "2013-05-27T09:30:00-04:00".
// Throws an Error whose message says what is wrong.
function isoWithOffset(local, zoneText) {
  const m = /^(\d{4})-(\d{2})-(\d{2})T(\d{2}):(\d{2})(?::(\d{2})(\.\d+)?)?$/.exec(local);
  if (!m) throw new Error("enter a date and a time");
  const clock = `${m[1]}-${m[2]}-${m[3]}T${m[4]}:${m[5]}:${m[6] || "00"}${m[7] || ""}`;
  const zone = zoneText.trim();
  if (/^(z|utc|gmt)$/i.test(zone)) return `${clock}Z`;
  const fixed = /^(?:utc|gmt)?\s*([+-])(\d{1,2})(?::?(\d{2}))?$/i.exec(zone);
  if (fixed) {
    const minutes = (fixed[1] === "-" ? -1 : 1) * (60 * +fixed[2] + +(fixed[3] || 0));
    if (+fixed[2] > 18 || +(fixed[3] || 0) > 59) throw new Error(`"${zone}" is not a UTC offset`);
    return clock + formatOffset(minutes);
  }
  try {
    // The instant whose wall clock in `zone` reads `clock`: two fixed-point steps
    // settle the offset (a clock time skipped by a DST change takes the later offset).
    const wall = Date.UTC(+m[1], +m[2] - 1, +m[3], +m[4], +m[5], +(m[6] || 0));
    let offset = zoneOffsetMinutes(zone, wall);
    offset = zoneOffsetMinutes(zone, wall - offset * 60000);
    return clock + formatOffset(offset);
  } catch {
    throw new Error(`unknown time zone "${zone}": use Z, an offset such as +02:00, or a name such as Europe/Paris`);
  }
}

// --- The request form ----------------------------------------------------------

const form = $("#request-form");
const kind = () => form.elements.kind.value;

// Every input that fills a request field gets an error line after it.
for (const input of form.querySelectorAll("[data-field], #time-zone")) {
  const note = element("p", { id: `${input.id}-error`, className: "field-error", hidden: true });
  input.closest(".field").append(note);
  input.setAttribute("aria-describedby", `${input.getAttribute("aria-describedby") || ""} ${note.id}`.trim());
}

function setPath(object, path, value) {
  const keys = path.split(".");
  let node = object;
  for (const k of keys.slice(0, -1)) node = node[k] ??= {};
  node[keys.at(-1)] = value;
}

// The reference balls of a lighting artist, on the ground in front of a
// camera of azimuth `yawDeg`: a chrome mirror (smooth chromium), a grey card's 18 %
// and a white 80 % ball, 0.5 m in radius, 5 m ahead, 1.3 m apart, left to
// right (docs/request-schema.md, objects).  Millimetre positions keep the
// request short.
function referenceBalls(yawDeg) {
  const yaw = (yawDeg * Math.PI) / 180;
  const forward = [Math.sin(yaw), Math.cos(yaw)], right = [Math.cos(yaw), -Math.sin(yaw)];
  const mm = (x) => Math.round(1000 * x) / 1000 + 0;  // + 0: no -0
  const at = (side) => [mm(5 * forward[0] + 1.3 * side * right[0]), mm(5 * forward[1] + 1.3 * side * right[1]), 0.5];
  return [
    { name: "chrome ball", shape: "sphere", material: { name: "chrome", roughness: 0 }, translate_m: at(-1), scale: 0.5 },
    { name: "grey ball", shape: "sphere", albedo: 0.18, translate_m: at(0), scale: 0.5 },
    { name: "white ball", shape: "sphere", albedo: 0.8, translate_m: at(1), scale: 0.5 },
  ];
}

// The cloud layer the Clouds controls describe, as the request's "clouds", or
// null with type "none": the default request stays a clear sky, unchanged.
// The type fills every field left out (docs/request-schema.md, clouds); the
// wind is sent the meteorological way, only when a speed is given.
function cloudLayers() {
  const type = $("#cloud-type").value;
  if (!type) return null;
  const layer = { type, coverage: $("#cloud-coverage").valueAsNumber };
  const speed = $("#cloud-wind-speed"), from = $("#cloud-wind-from");
  if (speed.value !== "" || speed.validity.badInput) {
    if (!Number.isFinite(speed.valueAsNumber)) throw { input: speed, message: "clouds.layers[0].wind.speed_m_s: must be a number" };
    if (!Number.isFinite(from.valueAsNumber)) throw { input: from, message: "clouds.layers[0].wind.from_deg: must be a number" };
    layer.wind = { speed_m_s: speed.valueAsNumber, from_deg: from.valueAsNumber };
  }
  return { layers: [layer] };
}

// The request body from the form, or throws {field input, message} for what
// the browser can tell is wrong before sending (unreadable numbers, time zone).
function readRequest() {
  const body = { camera: {} };
  for (const input of form.querySelectorAll("[data-type]")) {
    if (input.dataset.type === "boolean") {  // a checkbox: sent only when checked
      if (!input.disabled && input.checked) setPath(body, input.dataset.field, true);
      continue;
    }
    if (input.disabled || (input.value === "" && !input.validity.badInput)) continue;
    if (input.dataset.type === "string") { setPath(body, input.dataset.field, input.value); continue; }
    if (input.validity.badInput || !Number.isFinite(input.valueAsNumber))
      throw { input, message: `${input.dataset.field}: must be a number` };
    setPath(body, input.dataset.field, input.valueAsNumber);
  }
  if (body.camera.projection === "equirectangular") delete body.camera.fov_deg;  // ignored there
  if (kind() === "render" && $("#reference-balls").checked) body.objects = referenceBalls(body.camera.yaw_deg ?? 0);
  const clouds = cloudLayers();
  if (clouds) body.clouds = clouds;
  const zone = $("#time-zone").value;
  const timed = (input) => {
    try { return isoWithOffset(input.value, zone); } catch (error) {
      throw { input: input.value ? $("#time-zone") : input, message: error.message };
    }
  };
  if (kind() === "render") {
    body.time = timed($("#time-local"));
  } else {
    body.start = timed($("#time-local"));
    body.end = timed($("#time-end"));
    const split = $("#split-value");
    if (!Number.isFinite(split.valueAsNumber)) throw { input: split, message: "enter a number of frames or a step" };
    body[$("#split-kind").value] = split.valueAsNumber;
  }
  return body;
}

function clearErrors() {
  for (const note of form.querySelectorAll(".field-error")) { note.hidden = true; note.textContent = ""; }
  for (const input of form.querySelectorAll("[aria-invalid]")) input.removeAttribute("aria-invalid");
  const box = $("#form-problem");
  box.hidden = true;
  box.replaceChildren();
}

// The input that shows errors of request field `field` ("camera.width");
// an array's element ("objects[1].albedo") shows at the array's input.
function inputForField(field) {
  const array = /^([^[]+)\[/.exec(field)?.[1];
  for (const input of form.querySelectorAll("[data-field]")) {
    const names = input.dataset.field.split(" ");
    if (names.includes(field) || (array && names.includes(array))) return input;
  }
  return null;
}

function markInvalid(input, message) {
  input.setAttribute("aria-invalid", "true");
  const note = $(`#${input.id}-error`);
  note.textContent = note.textContent ? `${note.textContent}; ${message}` : message;
  note.hidden = false;
}

// A problem document (RFC 9457): each errors[] entry next to its input, the
// rest (and the title) in the box above the form.
function showProblem(problem, status) {
  clearErrors();
  const box = $("#form-problem");
  const title = problem?.title || `The server answered ${status}`;
  const errors = problem?.errors || [];
  const loose = element("ul");
  let first = null, placed = 0;
  for (const e of errors) {
    const message = e.message || `${e.field}: ${e.rule}`;
    const input = inputForField(e.field);
    if (input) { markInvalid(input, message); first ??= input; ++placed; } else loose.append(element("li", { textContent: message }));
  }
  // The detail repeats the errors' messages: said once, next to the fields.
  const summary = errors.length === 0 ? problem?.detail || "" :
    placed ? `${placed} field${placed > 1 ? "s" : ""} marked below.` : "";
  box.append(element("p", {}, [element("strong", { textContent: title }), summary ? ` ${summary}` : ""]));
  if (loose.childElementCount) box.append(loose);
  box.hidden = false;
  (first || box).focus();
}

async function submitForm(event) {
  event.preventDefault();
  clearErrors();
  let body;
  try { body = readRequest(); } catch (error) {
    if (!error.input) throw error;
    markInvalid(error.input, error.message);
    error.input.focus();
    return;
  }
  await submitBody(kind(), body, $("#submit"));
}

// POSTs a render ("render") or timelapse ("timelapse") body and shows what
// the server made of it (a 400 problem next to the form's fields).
async function submitBody(what, body, button) {
  if (button) button.disabled = true;
  try {
    const path = what === "render" ? "/v1/renders" : "/v1/timelapses";
    const res = await api(path, { method: "POST", body });
    if (!res.ok) { showProblem(res.data, res.status); return false; }
    const hash = what === "render" ? `#render=${res.data.id}` : `#timelapse=${res.data.id}`;
    if (location.hash === hash) showFromHash(); else location.hash = hash;  // the same id again: no hashchange
    refreshLists();
    return true;
  } finally {
    if (button) button.disabled = false;
  }
}

// A timelapse body has a start; a render body has none.
const kindOfBody = (body) => (body && typeof body === "object" && "start" in body ? "timelapse" : "render");

// --- Duplicate: a request back into the form and the JSON editor ----------------

// "2013-05-27T09:30:00-04:00" -> ["2013-05-27T09:30:00", "-04:00"].
function splitTime(text) {
  const m = /^(\d{4}-\d{2}-\d{2}T\d{2}:\d{2}(?::\d{2}(?:\.\d+)?)?)(Z|[+-]\d{2}:?\d{2})$/i.exec(text || "");
  return m ? [m[1], m[2].toUpperCase()] : null;
}

// Sets the form's inputs from a request body (a render's or a timelapse's,
// canonical or as written); fields the form has no input for stay in the
// JSON editor, which gets the whole body.
function fillForm(body) {
  const what = kindOfBody(body);
  form.elements.kind.value = what;
  const set = (id, value) => { $(id).value = value === null || value === undefined ? "" : String(value); };
  const l = body.location || {};
  set("#latitude", l.latitude_deg ?? 0);
  set("#longitude", l.longitude_deg ?? 0);
  set("#altitude", l.altitude_m ?? 0);
  const first = splitTime(what === "render" ? body.time : body.start);
  if (first) { set("#time-local", first[0]); set("#time-zone", first[1]); }
  if (what === "timelapse") {
    const end = splitTime(body.end);
    if (end) set("#time-end", end[0]);
    const byFrames = isNumber(body.frames);
    set("#split-kind", byFrames ? "frames" : "step_s");
    set("#split-value", byFrames ? body.frames : body.step_s);
  }
  const c = body.camera || {};
  set("#projection", c.projection || "equirectangular");
  set("#width", c.width ?? "");
  set("#height", c.height ?? "");
  set("#yaw", c.yaw_deg ?? 0);
  set("#pitch", c.pitch_deg ?? 0);
  set("#fov", c.projection && c.projection !== "equirectangular" ? c.fov_deg ?? "" : "");
  const material = body.atmosphere?.ground?.material;
  const known = material?.name && [...$("#ground-material").options].some((o) => o.value === material.name);
  set("#ground-material", known ? material.name : "");
  const roughness = material?.roughness;
  set("#ground-roughness", Array.isArray(roughness) ? roughness[0] : roughness ?? "");
  const balls = body.objects || [];
  $("#reference-balls").checked = balls.length === 3 && balls.every((o, i) => o.name === ["chrome ball", "grey ball", "white ball"][i]);
  const layer = body.clouds?.layers?.[0];
  set("#cloud-type", layer?.type && layer.type !== "custom" ? layer.type : "");
  if (layer) set("#cloud-coverage", layer.coverage ?? 0.4);
  const wind = layer?.wind_m_s || null;
  const speed = wind ? Math.hypot(wind[0], wind[1]) : layer?.wind?.speed_m_s;
  set("#cloud-wind-speed", speed > 0 ? +speed.toFixed(3) : "");
  // A wind from azimuth phi blows towards phi + 180 (api/cloud_fields.cpp).
  const from = wind ? (Math.atan2(-wind[0], -wind[1]) * 180 / Math.PI + 360) % 360 : layer?.wind?.from_deg;
  set("#cloud-wind-from", speed > 0 ? +from.toFixed(1) : 270);
  set("#method", body.method || "path");
  const q = body.quality || {};
  const uncapped = q.samples_per_pixel >= kUncappedSamples && (isNumber(q.target_relative_error) || isNumber(q.time_limit_s));
  set("#spp", uncapped ? "" : q.samples_per_pixel ?? "");
  set("#target-error", q.target_relative_error ?? "");
  set("#time-limit", q.time_limit_s ?? "");
  $("#adaptive").checked = q.adaptive === true;
  set("#name", body.name ?? "");
  $("#request-json").value = JSON.stringify(body, null, 2);
  $("#json-editor").open = true;
  clearErrors();
  updateFormMode();
}

function duplicate(body) {
  if (!body) return;
  fillForm(body);
  $("#new").scrollIntoView({ block: "start" });
  $("#name").focus({ preventScroll: true });
}

$("#json-from-form").addEventListener("click", () => {
  clearErrors();
  try { $("#request-json").value = JSON.stringify(readRequest(), null, 2); } catch (error) {
    if (!error.input) throw error;
    markInvalid(error.input, error.message);
  }
});

$("#json-submit").addEventListener("click", async () => {
  clearErrors();
  let body;
  try { body = JSON.parse($("#request-json").value); } catch (error) {
    showProblem({ title: "The JSON cannot be read", detail: String(error.message || error) }, 0);
    return;
  }
  await submitBody(kindOfBody(body), body, $("#json-submit"));
});

function updateFormMode() {
  document.body.dataset.kind = kind();
  $("#fov").disabled = $("#projection").value === "equirectangular";
  $("#ground-roughness").disabled = $("#ground-material").value === "";  // the default ground has none
  const clear = $("#cloud-type").value === "";  // no layer: its controls do nothing
  for (const id of ["#cloud-coverage", "#cloud-wind-speed", "#cloud-wind-from"]) $(id).disabled = clear;
  $("#cloud-coverage-value").value = `${Math.round(100 * $("#cloud-coverage").valueAsNumber)} %`;
  try {
    $("#time-preview").value = isoWithOffset($("#time-local").value, $("#time-zone").value);
  } catch (error) {
    $("#time-preview").value = `– (${error.message})`;
  }
}

// A new projection keeps the width and takes its usual shape: 2:1 lat-long,
// a square fisheye, a 16:9 perspective view.
$("#projection").addEventListener("change", () => {
  const width = $("#width").valueAsNumber;
  const aspect = { equirectangular: 1 / 2, fisheye: 1, perspective: 9 / 16 }[$("#projection").value];
  if (Number.isFinite(width) && aspect) $("#height").value = String(Math.max(1, Math.round(width * aspect)));
});

// A new cloud type starts from its own typical coverage (the defaults of
// common/clouds/cloud_spec.cpp), which the slider then changes.
$("#cloud-type").addEventListener("change", () => {
  const coverage = { cumulus: 0.4, stratocumulus: 0.7, stratus: 1, cirrus: 0.5 }[$("#cloud-type").value];
  if (coverage !== undefined) $("#cloud-coverage").value = String(coverage);
});

form.addEventListener("submit", submitForm);
form.addEventListener("input", updateFormMode);
form.addEventListener("change", updateFormMode);

$("#token").value = sessionStorage.getItem(kTokenKey) || "";
$("#token-form").addEventListener("submit", (event) => {
  event.preventDefault();
  const token = $("#token").value.trim();
  if (token) sessionStorage.setItem(kTokenKey, token); else sessionStorage.removeItem(kTokenKey);
  $("#token-state").value = token ? "Token in use for this tab." : "No token.";
  refreshLists();
  showFromHash();
});

// --- Server-Sent Events over fetch --------------------------------------------

// Reads text/event-stream frames ("id:", "event:", "data:" lines, a blank
// line ends a frame) and calls onEvent(type, data) for each; reconnects with
// Last-Event-ID when the stream breaks, stops after a terminal event.
class EventFeed {
  constructor(url, onEvent, onGone) {
    this.url = url;
    this.onEvent = onEvent;
    this.onGone = onGone;          // the stream ended without a terminal event and the job is over
    this.lastId = null;
    this.abort = new AbortController();
    this.run();
  }

  stop() { this.abort.abort(); }

  async run() {
    const { signal } = this.abort;
    while (!signal.aborted) {
      let ended = false;
      try {
        ended = await this.readOnce(signal);
      } catch (error) {
        if (signal.aborted) return;
      }
      if (ended) return;
      if (await this.onGone()) return;
      await sleep(kStreamRetryMs);
    }
  }

  // true when a terminal event arrived or the job does not exist.
  async readOnce(signal) {
    const headers = { Accept: "text/event-stream", ...authHeaders() };
    if (this.lastId !== null) headers["Last-Event-ID"] = this.lastId;
    const res = await fetch(this.url, { headers, signal, cache: "no-store" });
    if (res.status === 404) return true;
    if (!res.ok) return false;
    const reader = res.body.pipeThrough(new TextDecoderStream()).getReader();
    let buffer = "";
    for (;;) {
      const { value, done } = await reader.read();
      if (done) return false;
      buffer += value.replace(/\r\n?/g, "\n");
      let end;
      while ((end = buffer.indexOf("\n\n")) >= 0) {
        const frame = buffer.slice(0, end);
        buffer = buffer.slice(end + 2);
        if (this.dispatch(frame)) { reader.cancel().catch(() => {}); return true; }
      }
    }
  }

  dispatch(frame) {
    let type = "message", data = "", id = null;
    for (const line of frame.split("\n")) {
      if (line.startsWith(":")) continue;  // a keepalive comment
      const colon = line.indexOf(":");
      const name = colon < 0 ? line : line.slice(0, colon);
      const value = colon < 0 ? "" : line.slice(colon + 1).replace(/^ /, "");
      if (name === "event") type = value;
      else if (name === "data") data += data ? `\n${value}` : value;
      else if (name === "id") id = value;
    }
    if (id !== null) this.lastId = id;
    if (!data) return false;
    this.onEvent(type, JSON.parse(data));
    return kTerminal.has(type);
  }
}

// --- The render view -----------------------------------------------------------

const view = {
  id: null,
  feed: null,
  status: null,
  imageUrl: null,
  imageWanted: 0,   // bumped by every event; the image is fetched again while behind
  imageLoader: null,  // the id whose image loop runs (one per shown render)
  imageFetchedAt: -Infinity,
  announced: "",
  drawPending: false,
};

function showRender(id) {
  if (view.feed) view.feed.stop();
  if (view.imageUrl) URL.revokeObjectURL(view.imageUrl);
  Object.assign(view, { id, feed: null, status: null, imageUrl: null, imageWanted: 0, imageFetchedAt: -Infinity,
    imageLoader: null, announced: "" });
  $("#timelapse").hidden = true;
  $("#job").hidden = false;
  $("#job-id").textContent = id;
  $("#job-name").textContent = "Render";
  $("#job-request").textContent = "";
  $("#job-duplicate").disabled = $("#job-resubmit").disabled = true;
  $("#job-image").removeAttribute("src");
  $("#job-image-note").textContent = "Waiting for the first pass.";
  const base = `/v1/renders/${encodeURIComponent(id)}`;
  setDownload($("#job-png"), `${base}/image.png`, `${id}.png`);
  setDownload($("#job-exr"), `${base}/image.exr`, `${id}.exr`);
  api(base).then((res) => {
    if (view.id !== id) return;
    if (!res.ok) { showRenderMissing(res); return; }
    renderStatus(res.data, "status");
    if (!kTerminal.has(res.data.state)) {
      view.feed = new EventFeed(`${base}/events`, (type, data) => {
        if (view.id === id) renderStatus(data, type);
      }, async () => {
        const again = await api(base);
        if (view.id !== id) return true;
        if (again.ok) renderStatus(again.data, "status");
        return !again.ok || kTerminal.has(again.data.state);
      });
    }
  });
}

function showRenderMissing(res) {
  $("#job-state").textContent = "unavailable";
  $("#job-summary").textContent = res.data?.detail || `HTTP ${res.status}`;
  $("#job-cancel").disabled = true;
}

// One status document (an event's data or GET /v1/renders/{id}).
function renderStatus(status, type) {
  view.status = status;
  view.imageWanted += 1;
  loadImage();
  announce(status);
  if (!view.drawPending) {
    view.drawPending = true;
    requestAnimationFrame(() => { view.drawPending = false; drawStatus(view.status); });
  }
  if (kTerminal.has(type)) refreshLists();
}

// Screen readers hear the state and every tenth of the progress, not every event.
function announce(status) {
  const fraction = status.progress?.fraction ?? 0;
  const text = kTerminal.has(status.state) ? `Render ${status.state}.`
    : `Render ${status.state}, ${Math.floor(10 * fraction) * 10} percent.`;
  if (text !== view.announced) $("#job-live").textContent = view.announced = text;
}

function drawStatus(status) {
  const p = status.progress || {};
  $("#job-state").textContent = status.state;
  $("#job-state").dataset.state = status.state;
  const rms = status.error?.estimated_relative_rms;
  $("#job-name").textContent = titleOf(status);
  $("#job-summary").textContent = [
    isNumber(p.fraction) ? percent(p.fraction) : "",
    samplesText(p, status.request),
    isNumber(rms) ? `error ≈ ${percent(rms, 1)}` : "",
    isNumber(status.elapsed_s) ? `${seconds(status.elapsed_s)} elapsed` : "",
    isNumber(status.eta_s) ? `about ${seconds(status.eta_s)} left` : "",
  ].filter(Boolean).join(" · ");
  $("#job-progress").value = isNumber(p.fraction) ? p.fraction : 0;
  $("#job-cancel").disabled = kTerminal.has(status.state);
  const body = requestOf(status);
  const text = body ? JSON.stringify(body, null, 2) : "";
  if ($("#job-request").textContent !== text) $("#job-request").textContent = text;
  $("#job-duplicate").disabled = $("#job-resubmit").disabled = !body;
  drawDetails(status);
  drawErrorPlot($("#job-plot"), status.error?.history || [], status.method === "lut");
}

function drawDetails(status) {
  const p = status.progress || {};
  const rows = [
    ["Name", status.name],
    ["Place", placeText(status.request)],
    ["Time", timeText(status.request)],
    ["Camera", cameraText(status.request)],
    ["Method", status.approximate ? `${status.method} (approximate)` : status.method],
    ["Samples", samplesText(p, status.request)],
    ["Stopped by", status.stopped_by],
    ["Plan", status.plan ? `${status.plan.tiles} tiles × ${status.plan.batches} batches × ${status.plan.passes} passes; ` +
      `media ${(status.plan.constituents || []).join(", ") || "none"}` : null],
    ["Workers", (status.workers || []).map((w) => `${w.id} (${w.units})`).join(", ")],
    ["Failure", status.failure],
  ].filter(([, value]) => value !== null && value !== undefined && value !== "");
  $("#job-details").replaceChildren(...rows.flatMap(([k, v]) =>
    [element("dt", { textContent: k }), element("dd", { textContent: String(v) })]));
}

// Fetches the progressive PNG again while events arrived since the last
// fetch: one fetch at a time, at most one per kImageIntervalMs until the
// job is over, none before the first pass is merged (the server answers 409
// until then); the URL carries the event count so that no cache answers it.
// 404/409: no image (yet), the last one stays.
async function loadImage() {
  const id = view.id;
  if (!id || view.imageLoader === id) return;
  view.imageLoader = id;
  try {
    let loaded = 0;
    while (view.id === id && loaded < view.imageWanted) {
      const over = kTerminal.has(view.status?.state);
      if (!over && !(view.status?.progress?.samples_per_pixel > 0)) break;  // the next event tries again
      const wait = view.imageFetchedAt + kImageIntervalMs - performance.now();
      if (!over && wait > 0) { await sleep(wait); continue; }
      loaded = view.imageWanted;
      view.imageFetchedAt = performance.now();
      const blob = await fetchBlobUrl(`/v1/renders/${encodeURIComponent(id)}/image.png?event=${loaded}`);
      if (view.id !== id) { if (blob.url) URL.revokeObjectURL(blob.url); break; }
      if (blob.url) {
        const old = view.imageUrl;
        view.imageUrl = blob.url;
        const img = $("#job-image");
        img.src = blob.url;
        await img.decode().catch(() => {});
        if (old) URL.revokeObjectURL(old);
        $("#job-image-note").textContent = view.status?.state === "done" ? "Final image." : "Progressive image.";
      } else if (blob.status === 409) {
        $("#job-image-note").textContent = "Waiting for the first pass to cover the whole frame.";
      } else if (blob.status !== 0) {
        $("#job-image-note").textContent = `No image (HTTP ${blob.status}).`;
      }
    }
  } finally {
    if (view.imageLoader === id) view.imageLoader = null;
  }
}

// --- The error-vs-time plot (inline SVG, log-log) -------------------------------

function svg(tag, attributes = {}, text) {
  const node = document.createElementNS(kSvgNs, tag);
  for (const [k, v] of Object.entries(attributes)) node.setAttribute(k, v);
  if (text !== undefined) node.textContent = text;
  return node;
}

// [lo, hi] in whole decades around the values (at least one decade wide).
function decades(values) {
  let lo = Math.floor(Math.log10(Math.min(...values)));
  let hi = Math.ceil(Math.log10(Math.max(...values)));
  if (hi <= lo) hi = lo + 1;
  return [lo, hi];
}

const tickText = (e, unit) => unit === "%" ? `${+(100 * 10 ** e).toPrecision(3)} %` : `${+(10 ** e).toPrecision(3)} s`;

function drawErrorPlot(plot, history, lut) {
  const points = history.filter((h) => h.elapsed_s > 0 && h.estimated_relative_rms > 0)
    .map((h) => [h.elapsed_s, h.estimated_relative_rms]);
  const [W, H, left, right, top, bottom] = [480, 280, 64, 16, 16, 40];
  const title = svg("title", { id: "job-plot-title" });
  plot.replaceChildren(title);
  if (points.length === 0) {
    title.textContent = "Error against time: no estimate yet";
    plot.append(svg("text", { x: W / 2, y: H / 2, "text-anchor": "middle", class: "plot-empty" },
      lut ? "The LUT renderer has no Monte Carlo error estimate." : "No error estimate yet."));
    return;
  }
  const [x0, x1] = decades(points.map((p) => p[0]));
  const [y0, y1] = decades(points.map((p) => p[1]));
  const x = (t) => left + (Math.log10(t) - x0) / (x1 - x0) * (W - left - right);
  const y = (e) => top + (y1 - Math.log10(e)) / (y1 - y0) * (H - top - bottom);
  const axes = svg("g", { class: "plot-axes" });
  for (let e = x0; e <= x1; ++e) {
    axes.append(svg("line", { x1: x(10 ** e), x2: x(10 ** e), y1: top, y2: H - bottom, class: "plot-grid" }));
    axes.append(svg("text", { x: x(10 ** e), y: H - bottom + 16, "text-anchor": "middle" }, tickText(e, "s")));
  }
  for (let e = y0; e <= y1; ++e) {
    axes.append(svg("line", { x1: left, x2: W - right, y1: y(10 ** e), y2: y(10 ** e), class: "plot-grid" }));
    axes.append(svg("text", { x: left - 6, y: y(10 ** e) + 4, "text-anchor": "end" }, tickText(e, "%")));
  }
  axes.append(svg("text", { x: (left + W - right) / 2, y: H - 4, "text-anchor": "middle" }, "elapsed time"));
  plot.append(axes);
  // Slope −½ through the first point: where a sound Monte Carlo estimate goes.
  const [t0, e0] = points[0];
  const tEnd = 10 ** x1;
  plot.append(svg("line", { x1: x(t0), y1: y(e0), x2: x(tEnd), y2: y(e0 * Math.sqrt(t0 / tEnd)), class: "plot-reference" }));
  plot.append(svg("polyline", { points: points.map(([t, e]) => `${x(t)},${y(e)}`).join(" "), class: "plot-line" }));
  for (const [t, e] of points) {
    const dot = svg("circle", { cx: x(t), cy: y(e), r: 3, class: "plot-point" });
    dot.append(svg("title", {}, `${seconds(t)}: ${percent(e, 2)}`));
    plot.append(dot);
  }
  const [tl, el] = points.at(-1);
  title.textContent = `Error against time: ${percent(e0, 2)} at ${seconds(t0)}` +
    (points.length > 1 ? `, ${percent(el, 2)} at ${seconds(tl)} (${points.length} points)` : "");
}

$("#job-duplicate").addEventListener("click", () => duplicate(requestOf(view.status)));
$("#job-resubmit").addEventListener("click", () => {
  const body = requestOf(view.status);
  if (body) submitBody("render", body, $("#job-resubmit"));
});

$("#job-cancel").addEventListener("click", async () => {
  if (!view.id) return;
  const res = await api(`/v1/renders/${encodeURIComponent(view.id)}`, { method: "DELETE" });
  if (res.ok && res.data) renderStatus(res.data, res.data.state);
  refreshLists();
});

// --- The timelapse view ------------------------------------------------------------

const lapse = {
  id: null,
  timer: null,
  status: null,
  frames: new Map(),     // index -> {url, time, state, final}; url once the PNG is fetched,
                         // final once fetched from a done timelapse (it will not change)
  fetching: new Set(),
  shown: 0,
  player: null,
  abort: new AbortController(),
};

function showTimelapse(id) {
  stopTimelapse();
  lapse.id = id;
  $("#job").hidden = true;
  if (view.feed) view.feed.stop();
  view.id = null;
  $("#timelapse").hidden = false;
  $("#tl-id").textContent = id;
  $("#tl-name").textContent = "Timelapse";
  $("#tl-request").textContent = "";
  $("#tl-duplicate").disabled = $("#tl-resubmit").disabled = true;
  $("#tl-strip").replaceChildren();
  $("#tl-frame").removeAttribute("src");
  $("#tl-frame-caption").textContent = "No frame finished yet.";
  pollTimelapse();
}

function stopTimelapse() {
  clearTimeout(lapse.timer);
  pause();
  lapse.abort.abort();
  for (const f of lapse.frames.values()) if (f.url) URL.revokeObjectURL(f.url);
  Object.assign(lapse, { id: null, status: null, frames: new Map(), fetching: new Set(), shown: 0,
    abort: new AbortController() });
}

async function pollTimelapse() {
  const id = lapse.id;
  if (!id) return;
  const res = await api(`/v1/timelapses/${encodeURIComponent(id)}`).catch(() => null);
  if (lapse.id !== id || !res) return;
  if (!res.ok) {
    $("#tl-state").textContent = "unavailable";
    $("#tl-summary").textContent = res.data?.detail || `HTTP ${res.status}`;
    $("#tl-cancel").disabled = true;
    return;
  }
  drawTimelapse(res.data);
  if (!kTerminal.has(res.data.state)) lapse.timer = setTimeout(pollTimelapse, kTimelapsePollMs);
  else refreshLists();
}

function drawTimelapse(status) {
  lapse.status = status;
  const p = status.progress || {};
  $("#tl-state").textContent = status.state;
  $("#tl-state").dataset.state = status.state;
  $("#tl-summary").textContent = `${p.frames_done ?? 0} of ${p.frames_total ?? "?"} frames` +
    (isNumber(p.fraction) ? ` · ${percent(p.fraction)}` : "");
  $("#tl-progress").value = isNumber(p.fraction) ? p.fraction : 0;
  $("#tl-live").textContent = kTerminal.has(status.state) ? `Timelapse ${status.state}.`
    : `Timelapse ${status.state}, ${p.frames_done ?? 0} of ${p.frames_total ?? "?"} frames.`;
  $("#tl-cancel").disabled = kTerminal.has(status.state);
  $("#tl-name").textContent = status.name || "Timelapse";
  const body = requestOf(status);
  const text = body ? JSON.stringify(body, null, 2) : "";
  if ($("#tl-request").textContent !== text) $("#tl-request").textContent = text;
  $("#tl-duplicate").disabled = $("#tl-resubmit").disabled = !body;
  drawFiles(status);
  const frames = status.frames || [];
  $("#tl-seek").max = String(Math.max(0, frames.length - 1));
  syncStrip(frames);
  fetchFrames(frames);
}

function drawFiles(status) {
  const id = status.id || lapse.id;
  const base = `/v1/timelapses/${encodeURIComponent(id)}`;
  const video = status.video || {};
  const videoLink = $("#tl-video"), sheetLink = $("#tl-sheet");
  videoLink.hidden = !video.available;
  if (video.available) setDownload(videoLink, status.links?.video || `${base}/video.mp4`, `${id}.mp4`);
  const sheet = status.contact_sheet?.available === true;
  sheetLink.hidden = !sheet;
  if (sheet) setDownload(sheetLink, status.links?.contact_sheet || `${base}/contact_sheet.png`, `${id}-contact-sheet.png`);
  // The status says why there is no video (yet): no ffmpeg, being made, frames to go.
  const over = kTerminal.has(status.state);
  $("#tl-files-note").textContent = !video.available && video.reason ? `${over ? "No video" : "Video"}: ${video.reason}` :
    over ? "" : "The contact sheet and the video come when every frame is done.";
}

function syncStrip(frames) {
  syncRows($("#tl-strip"), frames, (f) => String(f.index),
    (f) => {
      const button = element("button", { type: "button", className: "thumb" },
        [element("img", { alt: "" }), element("span", { className: "thumb-label" })]);
      button.addEventListener("click", () => { pause(); showFrame(f.index); });
      return element("li", {}, button);
    },
    (li, f) => {
      const entry = lapse.frames.get(f.index) || {};
      lapse.frames.set(f.index, { ...entry, time: f.time, state: f.state, render_id: f.render_id });
      const label = `Frame ${f.index + 1}, ${f.time}, ${f.state}` +
        (isNumber(f.estimated_relative_rms) ? `, error ${percent(f.estimated_relative_rms, 1)}` : "");
      const button = li.firstChild;
      button.setAttribute("aria-label", label);
      button.title = label;
      button.dataset.state = f.state;
      li.querySelector(".thumb-label").textContent = entry.url ? "" : f.state;
    });
}

// Fetches the PNG of every finished frame not fetched yet, a few at a time;
// once the timelapse is done, each frame once more: its PNG is then the
// sequence's (one smoothed exposure) instead of the frame render's own.
// A failed fetch is tried again at the next poll, or after kTimelapsePollMs
// when the timelapse is over (nothing polls then).
function fetchFrames(frames) {
  const id = lapse.id;
  const final = lapse.status?.state === "done";
  const base = `/v1/timelapses/${encodeURIComponent(id)}/frames`;
  for (const f of frames) {
    const entry = lapse.frames.get(f.index);
    if (f.state !== "done" || (entry.url && (entry.final || !final)) || lapse.fetching.has(f.index)) continue;
    if (lapse.fetching.size >= kThumbnailFetches) break;
    lapse.fetching.add(f.index);
    fetchBlobUrl(`${base}/${f.index}.png`, lapse.abort.signal).then((blob) => {
      if (lapse.id !== id) { if (blob.url) URL.revokeObjectURL(blob.url); return; }
      lapse.fetching.delete(f.index);
      if (blob.url) {
        frameFetched(f.index, blob.url, final);
        fetchFrames(lapse.status?.frames || []);
      } else if (kTerminal.has(lapse.status?.state)) {
        setTimeout(() => { if (lapse.id === id) fetchFrames(lapse.status?.frames || []); }, kTimelapsePollMs);
      }
    }).catch(() => {});
  }
}

// A frame's PNG arrived: its thumbnail, and the big view when it shows that
// frame or nothing yet.
function frameFetched(index, url, final) {
  const entry = lapse.frames.get(index);
  const old = entry.url;
  Object.assign(entry, { url, final });
  const li = [...$("#tl-strip").children].find((node) => node.dataset.key === String(index));
  if (li) {
    li.querySelector("img").src = url;
    li.querySelector(".thumb-label").textContent = "";
    li.dataset.exposure = final ? "sequence" : "frame";  // which PNG the thumbnail is
  }
  if (!$("#tl-frame").getAttribute("src") || lapse.shown === index) showFrame(index);
  if (old) URL.revokeObjectURL(old);
}

function showFrame(index) {
  const f = lapse.frames.get(index);
  lapse.shown = index;
  $("#tl-seek").value = String(index);
  const total = lapse.status?.frames?.length ?? 0;
  if (f?.url) {
    $("#tl-frame").src = f.url;
    $("#tl-frame").alt = `Frame ${index + 1} of ${total}, ${f.time}`;
  }
  $("#tl-frame-caption").textContent = f ? `Frame ${index + 1} of ${total}: ${f.time} (${f.url ? f.state : "not rendered yet"})` : "";
}

// Plays the fetched frames in order, looping; frames not fetched yet are skipped.
function play() {
  const ready = () => [...lapse.frames.entries()].filter(([, f]) => f.url).map(([i]) => i).sort((a, b) => a - b);
  if (ready().length === 0) return;
  const step = () => {
    const order = ready();
    const next = order.find((i) => i > lapse.shown) ?? order[0];
    showFrame(next);
    const fps = Math.min(30, Math.max(1, +$("#tl-fps").value || 4));
    lapse.player = setTimeout(step, 1000 / fps);
  };
  $("#tl-play").textContent = "Pause";
  $("#tl-play").setAttribute("aria-pressed", "true");
  step();
}

function pause() {
  clearTimeout(lapse.player);
  lapse.player = null;
  $("#tl-play").textContent = "Play";
  $("#tl-play").setAttribute("aria-pressed", "false");
}

$("#tl-play").addEventListener("click", () => (lapse.player ? pause() : play()));
$("#tl-duplicate").addEventListener("click", () => duplicate(requestOf(lapse.status)));
$("#tl-resubmit").addEventListener("click", () => {
  const body = requestOf(lapse.status);
  if (body) submitBody("timelapse", body, $("#tl-resubmit"));
});
$("#tl-seek").addEventListener("input", () => { pause(); showFrame(+$("#tl-seek").value); });
$("#tl-cancel").addEventListener("click", async () => {
  if (!lapse.id) return;
  await api(`/v1/timelapses/${encodeURIComponent(lapse.id)}`, { method: "DELETE" });
  clearTimeout(lapse.timer);
  pollTimelapse();
});

// --- Lists: renders, timelapses, workers ------------------------------------------

function cancelButton(label, path) {
  const button = element("button", { type: "button", className: "cancel", textContent: "Cancel" });
  button.setAttribute("aria-label", label);
  button.addEventListener("click", async () => {
    button.disabled = true;
    await api(path, { method: "DELETE" });
    refreshLists();
  });
  return button;
}

// A finished job's Cancel button is disabled and out of sight (its cell keeps
// its width, so the columns do not jump when a render ends).
function setCancellable(button, cancellable) {
  button.disabled = !cancellable;
  button.style.visibility = cancellable ? "" : "hidden";
}

// The state filter: "" shows every state.
const stateShown = (state) => !$("#state-filter").value || $("#state-filter").value === state;

// The list's title cell: name (or a short description), then place, time,
// method and camera on a line of their own, and the id.
// Renders have a thumbnail before the text.
function titleCell(kindName, item) {
  const open = element("a", { href: `#${kindName}=${item.id}`, className: "job-link" });
  const text = element("div", { className: "title-text" }, [open, element("span", { className: "job-meta" }),
    element("code", { className: "job-id", textContent: shortId(item.id), title: item.id })]);
  const thumb = kindName === "render" ? [element("img", { className: "list-thumb", alt: "" })] : [];
  return element("th", { scope: "row" }, element("div", { className: "title-box" }, [...thumb, text]));
}

function updateTitleCell(cell, kindName, item) {
  const link = cell.querySelector("a");
  const title = titleOf(item);
  if (link.textContent !== title) link.textContent = title;
  link.setAttribute("aria-label", `Show ${kindName} ${title} (${item.id})`);
  link.classList.toggle("unnamed", !item.name);
  const meta = [placeText(item.request), timeText(item.request), item.method, cameraText(item.request)]
    .filter(Boolean).join(" · ");
  const line = cell.querySelector(".job-meta");
  if (line.textContent !== meta) line.textContent = meta;
}

// Thumbnails of done renders: each fetched once (the final image does not
// change), a few at a time, kept as object URLs by id.
const thumbnails = new Map();  // id -> object URL, or null while fetching
function loadThumbnail(row, id) {
  const img = row.querySelector("img.list-thumb");
  const url = thumbnails.get(id);
  if (url) { if (img.getAttribute("src") !== url) img.src = url; return; }
  if (thumbnails.has(id) || [...thumbnails.values()].filter((v) => v === null).length >= kThumbnailFetches) return;
  thumbnails.set(id, null);
  fetchBlobUrl(`/v1/renders/${encodeURIComponent(id)}/image.png?width=${kListThumbnailWidth}`).then((blob) => {
    if (!blob.url) { thumbnails.delete(id); return; }
    thumbnails.set(id, blob.url);
    const shown = $(`#jobs-body tr[data-key="${CSS.escape(id)}"] img.list-thumb`);
    if (shown) shown.src = blob.url;
  });
}

function drawRenders(list) {
  syncRows($("#jobs-body"), list, (job) => job.id, (job) => {
    const bar = element("progress", { max: 1 });
    bar.setAttribute("aria-label", `Progress of render ${job.id}`);
    const row = element("tr", {}, [titleCell("render", job),
      element("td"), element("td", {}, [bar, element("span", { className: "progress-text" })]), element("td"),
      element("td"), element("td", {}, cancelButton(`Cancel render ${job.id}`, `/v1/renders/${encodeURIComponent(job.id)}`))]);
    row.dataset.jobId = job.id;
    return row;
  }, (row, job) => {
    const fraction = job.progress?.fraction ?? 0;
    const rms = job.error?.estimated_relative_rms;
    updateTitleCell(row.cells[0], "render", job);
    row.cells[1].textContent = job.state;
    row.cells[1].dataset.state = job.state;
    row.dataset.state = job.state;
    row.cells[2].querySelector("progress").value = fraction;
    row.cells[2].querySelector("span").textContent = ` ${samplesText(job.progress, job.request) || percent(fraction)}`;
    row.cells[3].textContent = isNumber(rms) ? percent(rms, 1) : job.approximate ? "approximate" : "–";
    row.cells[4].textContent = job.created_unix ? new Date(job.created_unix * 1000).toLocaleString() : "";
    setCancellable(row.cells[5].querySelector("button"), !kTerminal.has(job.state));
    row.classList.toggle("selected", job.id === view.id);
    row.hidden = !stateShown(job.state);
    if (job.state === "done" && !job.expired) loadThumbnail(row, job.id);
  });
  const shown = list.filter((job) => stateShown(job.state)).length;
  $("#jobs-note").textContent = list.length === 0 ? "No renders yet." :
    shown === 0 ? `None of the ${list.length} latest renders is ${$("#state-filter").value}.` : "";
}

function drawTimelapses(list) {
  syncRows($("#timelapses-body"), list, (t) => t.id, (t) => {
    const row = element("tr", {}, [titleCell("timelapse", t), element("td"), element("td"), element("td"),
      element("td", {}, cancelButton(`Cancel timelapse ${t.id}`, `/v1/timelapses/${encodeURIComponent(t.id)}`))]);
    return row;
  }, (row, t) => {
    updateTitleCell(row.cells[0], "timelapse", t);
    row.cells[1].textContent = t.state;
    row.cells[1].dataset.state = t.state;
    row.dataset.state = t.state;
    row.cells[2].textContent = `${t.progress?.frames_done ?? 0} of ${t.progress?.frames_total ?? "?"}`;
    row.cells[3].textContent = t.created_unix ? new Date(t.created_unix * 1000).toLocaleString() : "";
    setCancellable(row.cells[4].querySelector("button"), !kTerminal.has(t.state));
    row.classList.toggle("selected", t.id === lapse.id);
    row.hidden = !stateShown(t.state);
  });
}

// Drain: the server sends the worker no new units (those in flight finish);
// Resume undoes it.
function drainButton() {
  const button = element("button", { type: "button", className: "secondary drain" });
  button.addEventListener("click", async () => {
    const id = button.closest("tr").dataset.key;
    const action = button.dataset.action;
    button.disabled = true;
    const res = await api(`/v1/workers/${encodeURIComponent(id)}/${action}`, { method: "POST" });
    if (!res.ok) $("#workers-note").textContent = res.data?.detail || `HTTP ${res.status}`;
    await refreshLists();
    button.disabled = false;
  });
  return button;
}

function drawWorkers(list) {
  syncRows($("#workers-body"), list, (w) => w.id, () => element("tr", {}, [element("th", { scope: "row" }),
    element("td"), element("td"), element("td"), element("td"), element("td", {}, [element("span"), drainButton()])]),
  (row, w) => {
    row.cells[0].textContent = w.id;
    row.cells[1].textContent = w.cores ?? "–";
    row.cells[2].textContent = w.units_in_flight ?? "–";
    row.cells[3].textContent = w.units_done ?? "–";
    row.cells[4].textContent = isNumber(w.last_seen_s) ? `${seconds(w.last_seen_s)} ago` : "–";
    const draining = w.draining === true;
    row.dataset.draining = String(draining);
    row.cells[5].querySelector("span").textContent = draining ? "draining " : "";
    const button = row.cells[5].querySelector("button");
    button.dataset.action = draining ? "resume" : "drain";
    button.textContent = draining ? "Resume" : "Drain";
    button.setAttribute("aria-label", `${draining ? "Resume" : "Drain"} worker ${w.id}`);
  });
  $("#workers-note").textContent = list.length ? "" : "No worker is connected: renders wait in the queue.";
}

function listProblem(note, res) {
  note.textContent = res.status === 0 ? "The server cannot be reached." :
    res.status === 401 ? "The server needs an access token (above)." : res.data?.detail || `HTTP ${res.status}`;
}

let refreshing = false;
async function refreshLists() {
  if (refreshing) return;
  refreshing = true;
  try {
    const [renders, timelapses, workers] = await Promise.all([
      api("/v1/renders?limit=20"), api("/v1/timelapses?limit=20"), api("/v1/workers")]);
    if (renders.ok) drawRenders(renders.data.renders || []); else listProblem($("#jobs-note"), renders);
    if (workers.ok) drawWorkers(workers.data.workers || []); else listProblem($("#workers-note"), workers);
    if (timelapses.ok) {
      const list = timelapses.data.timelapses || [];
      drawTimelapses(list);
      $("#timelapses-note").textContent = list.length ? "" : "No timelapses yet.";
    } else if (timelapses.status === 404) {
      $("#timelapses-note").textContent = "This server has no timelapse routes.";
    } else {
      listProblem($("#timelapses-note"), timelapses);
    }
  } finally {
    refreshing = false;
  }
}

// --- What is shown: the location hash ------------------------------------------------

function showFromHash() {
  const m = /^#(render|timelapse)=([A-Za-z0-9_-]{1,64})$/.exec(location.hash);
  if (!m) return;
  if (m[1] === "render") { stopTimelapse(); showRender(m[2]); } else showTimelapse(m[2]);
  for (const row of $("#jobs-body").children) row.classList.toggle("selected", row.dataset.key === view.id);
  $(m[1] === "render" ? "#job" : "#timelapse").scrollIntoView({ block: "nearest" });
}

$("#state-filter").addEventListener("change", () => {
  for (const row of document.querySelectorAll("#jobs-body tr, #timelapses-body tr")) row.hidden = !stateShown(row.dataset.state);
  refreshLists();
});
window.addEventListener("hashchange", showFromHash);
updateFormMode();
refreshLists();
showFromHash();
setInterval(() => { if (!document.hidden) refreshLists(); }, kListRefreshMs);
