// The viewer: pick a robot, set its joints or type a target, and see every IK solution drawn.
// It uses the public API only: GET /v1/robots, GET /v1/robots/{id}, and POST .../fk, .../render, .../ik.
// Joint values are sent with "angle_unit": "deg". When the robot carries link shapes, every request also sends
// "collisions" (self-collision, the margin and the box obstacles added here), so the pictures draw the shapes
// and mark colliding links, and IK rejects the colliding solutions.
"use strict";

const $ = (selector) => document.querySelector(selector);
// lastRequest and lastAnswer: the IK body the last "Solve IK" sent and its JSON answer
const state = { robot: null, description: null, joints: [], obstacles: [], solved: false, lastRequest: null,
                lastAnswer: null };

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
  state.solved = false;
  state.obstacles = [];  // in the length unit of the robot they were added for
  showObstacles();
  if (!id) return;
  const description = await call("GET", `/v1/robots/${encodeURIComponent(id)}`);
  state.description = description;
  const shaped = (description.collision || []).length > 0;
  $("#check-collisions").disabled = !shaped;
  $("#check-collisions").title = shaped ? "" : "this robot carries no link shapes";
  $("#length-unit").textContent = description.length_unit;
  const unit = description.length_unit === "mm" ? 1000 : 1;
  $("#box-center").value = [0.4, 0, -0.05].map((v) => v * unit).join(", ");
  $("#box-size").value = [0.6, 0.6, 0.1].map((v) => v * unit).join(", ");
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
  const collisions = collisionOptions();
  const fk = await call("POST", `/v1/robots/${id}/fk`,
    withCollisions({ joints: state.joints, angle_unit: "deg" }, collisions));
  const svg = await call("POST", `/v1/robots/${id}/render`,
    withCollisions({ joints: [state.joints], angle_unit: "deg", view: $("#view").value,
                     captions: ["current joints"], panel_size: 360 }, collisions), "image/svg+xml");
  $("#current-picture").innerHTML = svg;
  showClearance(fk, collisions);
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

// --------------------------------------------------------------------------- collisions

/** The requests' "collisions": null when the robot has no link shapes or the check is off. */
function collisionOptions() {
  if (!state.description || !(state.description.collision || []).length || !$("#check-collisions").checked) {
    return null;
  }
  return { self: true, margin: Math.max(0, Number($("#margin").value) || 0), obstacles: state.obstacles };
}

function withCollisions(body, collisions) {
  return collisions ? { ...body, collisions } : body;
}

function describeContacts(contacts) {
  return contacts.map((c) => `${c.a} – ${c.b} (${c.distance.toFixed(4)})`).join(", ");
}

function showClearance(fk, collisions) {
  const line = $("#clearance");
  line.classList.toggle("colliding", Boolean(collisions && fk.collisions && fk.collisions.length));
  if (!collisions) { line.textContent = ""; return; }
  line.textContent = fk.collisions.length ? `current joints collide: ${describeContacts(fk.collisions)}` :
    fk.clearance === null || fk.clearance === undefined ? "current joints: no pair checked" :
    `current joints: clear by ${fk.clearance.toFixed(4)} ${state.description.length_unit}`;
}

function parseTriple(text, what) {
  const values = text.split(/[\s,]+/).filter((v) => v !== "").map(Number);
  if (values.length !== 3 || values.some((v) => !Number.isFinite(v))) {
    throw new Error(`${what} must be three numbers, as "0.4, 0, -0.05"`);
  }
  return values;
}

function showObstacles() {
  const list = $("#obstacles");
  list.innerHTML = "";
  state.obstacles.forEach((obstacle, index) => {
    const item = document.createElement("li");
    item.className = "obstacle";
    item.dataset.name = obstacle.name;
    item.textContent = `${obstacle.name}: box at (${obstacle.box.center.join(", ")}), size ` +
      `(${obstacle.box.size.join(", ")})`;
    const remove = document.createElement("button");
    remove.type = "button";
    remove.textContent = "remove";
    remove.addEventListener("click", () => removeObstacle(index).catch(showError));
    item.append(remove);
    list.append(item);
  });
  list.dataset.count = String(state.obstacles.length);
}

/** Redraw the current joints and, once IK has been solved, solve again: the survivors of the new scene. */
async function collisionsChanged() {
  showObstacles();
  await showCurrent(false);
  if (state.solved) await solve();
}

/** Add a box obstacle (world frame, the robot's length unit); the form's values unless given. */
async function addBox(name, center, size) {
  showError(null);
  if (!state.robot) throw new Error("choose a robot first");
  if (!(state.description.collision || []).length) {
    throw new Error("this robot carries no link shapes: there is nothing to check an obstacle against");
  }
  name = (name === undefined ? $("#box-name").value : name).trim();
  center = center || parseTriple($("#box-center").value, "the centre");
  size = size || parseTriple($("#box-size").value, "the size");
  if (!name) throw new Error("give the box a name");
  if (state.obstacles.some((o) => o.name === name)) throw new Error(`there is already an obstacle named ${name}`);
  if (size.some((v) => v <= 0)) throw new Error("the size must be three numbers > 0");
  state.obstacles.push({ name, box: { center, size } });
  $("#box-name").value = `box ${state.obstacles.length + 1}`;
  if (!$("#check-collisions").checked) $("#check-collisions").checked = true;
  await collisionsChanged();
}

async function removeObstacle(index) {
  showError(null);
  state.obstacles.splice(index, 1);
  await collisionsChanged();
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
  const collisions = collisionOptions();
  const body = withCollisions({ target, reference: state.joints, angle_unit: "deg", filter_limits: false },
                              collisions);
  $("#summary").textContent = "solving…";
  for (const key of ["count", "rejected", "colliding", "obstacles"]) delete $("#summary").dataset[key];
  const answer = await call("POST", `/v1/robots/${id}/ik`, body);
  const picture = await call("POST", `/v1/robots/${id}/ik?render=${$("#view").value}`, body, "image/svg+xml");
  state.solved = true;
  state.lastRequest = body;
  state.lastAnswer = answer;
  $("#solutions").innerHTML = picture;
  const rows = $("#solution-table tbody");
  rows.innerHTML = "";
  answer.solutions.forEach((solution, index) => {
    const row = document.createElement("tr");
    row.className = solution.within_limits ? "within" : "outside";
    const branch = Object.entries(solution.branch).map(([k, v]) => `${k} ${v}`).join(", ");
    const limits = solution.within_limits ? "within" :
      "outside: " + solution.violations.map((v) => state.description.joints[v.joint].name || `q${v.joint + 1}`).join(", ");
    const clearance = solution.clearance === null || solution.clearance === undefined ? "" :
      solution.clearance.toFixed(4);
    row.innerHTML = `<td>${index + 1}</td><td class="joints">${solution.joints.map((v) => v.toFixed(2)).join(", ")}</td>` +
      `<td>${branch}</td><td>${limits}</td><td class="clearance">${clearance}</td>` +
      `<td>${largestMove(solution.joints, state.joints).toFixed(2)}</td>`;
    row.addEventListener("click", () => setJoints(solution.joints).catch(showError));
    rows.append(row);
  });
  const panels = document.querySelectorAll("#solutions g.configuration").length;
  const outside = answer.solutions.filter((s) => !s.within_limits).length;
  let summary = `${answer.status}: ${answer.solutions.length} solutions in ${panels} arm configurations ` +
    `(${outside} outside the limits), nearest the current joints first; ` +
    `solver ${answer.solver.method}, ${answer.solver.structure}${answer.solver.complete ? ", complete" : ""}.`;
  const colliding = answer.rejected.filter((s) => s.collisions && s.collisions.length).length;
  if (collisions) {
    const n = collisions.obstacles.length;
    summary += ` Collisions checked (self and ${n} obstacle${n === 1 ? "" : "s"}, margin ${collisions.margin}):` +
      ` colliding links are drawn red.`;
  }
  if (answer.detail) summary += ` ${answer.detail}`;
  $("#summary").textContent = summary;
  $("#summary").dataset.rejected = String(answer.rejected.length);
  $("#summary").dataset.colliding = String(colliding);
  $("#summary").dataset.obstacles = String(collisions ? collisions.obstacles.length : 0);
  $("#summary").dataset.panels = String(panels);
  $("#summary").dataset.count = String(answer.solutions.length);  // last: tests wait for it
}

// --------------------------------------------------------------------------- wiring

$("#api-key").value = sessionStorage.getItem("kin-api-key") || "";
$("#robot").addEventListener("change", (event) => chooseRobot(event.target.value).catch(showError));
$("#view").addEventListener("change", () => showCurrent(false).catch(showError));
$("#use-current").addEventListener("click", useCurrentPose);
$("#solve").addEventListener("click", () => solve().catch((error) => { $("#summary").textContent = ""; showError(error); }));
$("#api-key").addEventListener("change", () => loadRobots().catch(showError));
$("#add-box").addEventListener("click", () => addBox().catch(showError));
$("#check-collisions").addEventListener("change", () => collisionsChanged().catch(showError));
$("#margin").addEventListener("change", () => collisionsChanged().catch(showError));
window.kinematicsViewer = { chooseRobot, setJoints, solve, addBox, removeObstacle, state };
loadRobots().catch(showError);
