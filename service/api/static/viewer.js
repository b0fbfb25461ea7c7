// The viewer: pick a robot, set its joints or type a target, and see every IK solution drawn.
// It uses the public API only: GET /v1/robots, GET /v1/robots/{id}, and POST .../fk, .../render, .../ik.
// Joint values are sent with "angle_unit": "deg".
"use strict";

const $ = (selector) => document.querySelector(selector);
const state = { robot: null, description: null, joints: [] };

function headers() {
  const key = $("#api-key").value.trim();
  sessionStorage.setItem("kin-api-key", key);
  return key ? { "Content-Type": "application/json", "X-API-Key": key } : { "Content-Type": "application/json" };
}

async function call(method, path, body, accept) {
  const options = { method, headers: headers() };
  if (body !== undefined) options.body = JSON.stringify(body);
  if (accept) options.headers.Accept = accept;
  const response = await fetch(path, options);
  const text = await response.text();
  if (!response.ok) {
    let detail = text;
    try { detail = JSON.parse(text).detail || text; } catch (_) { /* not JSON */ }
    throw new Error(`${method} ${path}: ${response.status} ${detail}`);
  }
  return accept === "image/svg+xml" ? text : JSON.parse(text);
}

function showError(error) {
  $("#error").textContent = error ? String(error.message || error) : "";
}

// --------------------------------------------------------------------------- robots and joints

async function loadRobots() {
  const listed = await call("GET", "/v1/robots");
  const select = $("#robot");
  select.innerHTML = "";
  select.append(new Option("choose a robot…", ""));
  for (const robot of listed.robots) {
    select.append(new Option(`${robot.id}: ${robot.name || robot.id} (${robot.dof} joints)`, robot.id));
  }
  select.dataset.loaded = String(listed.robots.length);
}

function jointRange(joint, angleUnit) {
  const toDeg = joint.type === "revolute" && angleUnit === "rad" ? 180 / Math.PI : 1;
  const fallback = joint.type === "revolute" ? [-180, 180] : [-1, 1];
  const lower = joint.limits && joint.limits.lower !== null ? joint.limits.lower * toDeg : fallback[0];
  const upper = joint.limits && joint.limits.upper !== null ? joint.limits.upper * toDeg : fallback[1];
  return [lower, upper];
}

async function chooseRobot(id) {
  showError(null);
  state.robot = id || null;
  $("#joints").innerHTML = "";
  $("#solutions").innerHTML = "";
  $("#solution-table tbody").innerHTML = "";
  if (!id) return;
  const description = await call("GET", `/v1/robots/${encodeURIComponent(id)}`);
  state.description = description;
  $("#robot-info").textContent = `${description.name || id}: ${description.joints.length} joints, ` +
    `${description.convention} DH, lengths in ${description.length_unit}. ${description.source || ""}`;
  state.joints = description.joints.map(() => 0);
  description.joints.forEach((joint, index) => {
    const [lower, upper] = jointRange(joint, description.angle_unit);
    const row = document.createElement("div");
    row.className = "joint";
    const step = joint.type === "revolute" ? 0.5 : (upper - lower) / 400;
    row.innerHTML = `<span>${joint.name || "q" + (index + 1)} <span class="muted">${joint.type[0]}</span></span>` +
      `<input type="range" min="${lower}" max="${upper}" step="${step}" value="0" data-joint="${index}">` +
      `<input type="number" step="any" value="0" data-joint="${index}">`;
    $("#joints").append(row);
  });
  for (const input of document.querySelectorAll("#joints input")) {
    input.addEventListener("input", (event) => setJoint(Number(event.target.dataset.joint), event.target.value));
  }
  $("#joints").dataset.robot = id;
  await showCurrent(true);
}

function setJoint(index, value, quiet) {
  state.joints[index] = Number(value);
  for (const input of document.querySelectorAll(`#joints input[data-joint="${index}"]`)) {
    if (Number(input.value) !== state.joints[index]) input.value = String(state.joints[index]);
  }
  if (!quiet) scheduleCurrent();
}

/** Set every joint at once (degrees for revolute joints), redraw and use the new pose as the target. */
async function setJoints(values) {
  values.forEach((value, index) => setJoint(index, value, true));
  await showCurrent(true);
}

let pending = null;
function scheduleCurrent() {
  clearTimeout(pending);
  pending = setTimeout(() => showCurrent(false).catch(showError), 120);
}

async function showCurrent(asTarget) {
  if (!state.robot) return;
  const id = encodeURIComponent(state.robot);
  const fk = await call("POST", `/v1/robots/${id}/fk`, { joints: state.joints, angle_unit: "deg" });
  const svg = await call("POST", `/v1/robots/${id}/render`,
    { joints: [state.joints], angle_unit: "deg", view: $("#view").value, captions: ["current joints"],
      panel_size: 360 }, "image/svg+xml");
  $("#current-picture").innerHTML = svg;
  const p = fk.pose.position.map((v) => v.toFixed(4)).join(", ");
  const q = fk.pose.quaternion_wxyz.map((v) => v.toFixed(4)).join(", ");
  $("#tool-pose").textContent = `tool position (${p}), quaternion wxyz (${q})`;
  state.pose = fk.pose;
  if (asTarget || !$("#target").value.trim()) useCurrentPose();
}

function useCurrentPose() {
  if (!state.pose) return;
  $("#target").value = JSON.stringify({ matrix: state.pose.matrix.map((row) => row.map((v) => +v.toFixed(12))) });
}

// --------------------------------------------------------------------------- IK

function largestMove(a, b) {
  return Math.max(...a.map((value, i) => Math.abs(value - b[i])));
}

async function solve() {
  showError(null);
  if (!state.robot) throw new Error("choose a robot first");
  let target;
  try { target = JSON.parse($("#target").value); } catch (error) { throw new Error(`target is not JSON: ${error}`); }
  const id = encodeURIComponent(state.robot);
  const body = { target, reference: state.joints, angle_unit: "deg", filter_limits: false };
  $("#summary").textContent = "solving…";
  delete $("#summary").dataset.count;
  const answer = await call("POST", `/v1/robots/${id}/ik`, body);
  const picture = await call("POST", `/v1/robots/${id}/ik?render=${$("#view").value}`, body, "image/svg+xml");
  $("#solutions").innerHTML = picture;
  const rows = $("#solution-table tbody");
  rows.innerHTML = "";
  answer.solutions.forEach((solution, index) => {
    const row = document.createElement("tr");
    row.className = solution.within_limits ? "within" : "outside";
    const branch = Object.entries(solution.branch).map(([k, v]) => `${k} ${v}`).join(", ");
    const limits = solution.within_limits ? "within" :
      "outside: " + solution.violations.map((v) => state.description.joints[v.joint].name || `q${v.joint + 1}`).join(", ");
    row.innerHTML = `<td>${index + 1}</td><td class="joints">${solution.joints.map((v) => v.toFixed(2)).join(", ")}</td>` +
      `<td>${branch}</td><td>${limits}</td><td>${largestMove(solution.joints, state.joints).toFixed(2)}</td>`;
    row.addEventListener("click", () => setJoints(solution.joints).catch(showError));
    rows.append(row);
  });
  const panels = document.querySelectorAll("#solutions g.configuration").length;
  const outside = answer.solutions.filter((s) => !s.within_limits).length;
  let summary = `${answer.status}: ${answer.solutions.length} solutions in ${panels} arm configurations ` +
    `(${outside} outside the limits), nearest the current joints first; ` +
    `solver ${answer.solver.method}, ${answer.solver.structure}${answer.solver.complete ? ", complete" : ""}.`;
  if (answer.detail) summary += ` ${answer.detail}`;
  $("#summary").textContent = summary;
  $("#summary").dataset.count = String(answer.solutions.length);
  $("#summary").dataset.panels = String(panels);
}

// --------------------------------------------------------------------------- wiring

$("#api-key").value = sessionStorage.getItem("kin-api-key") || "";
$("#robot").addEventListener("change", (event) => chooseRobot(event.target.value).catch(showError));
$("#view").addEventListener("change", () => showCurrent(false).catch(showError));
$("#use-current").addEventListener("click", useCurrentPose);
$("#solve").addEventListener("click", () => solve().catch((error) => { $("#summary").textContent = ""; showError(error); }));
$("#api-key").addEventListener("change", () => loadRobots().catch(showError));
window.kinematicsViewer = { chooseRobot, setJoints, solve };
loadRobots().catch(showError);
