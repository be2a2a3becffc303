// The live page of `workbook serve`: the report replaced as the server pushes it (server-sent
// events), the inputs sent back as they change. Served as a file of its own: the page's
// Content-Security-Policy allows no inline script.
(function () {
  "use strict";
  const body = document.body;
  const token = body.dataset.token;
  const sheet = body.dataset.sheet;
  const report = document.getElementById("wb-report");
  const banner = document.getElementById("wb-error");
  const form = document.getElementById("wb-inputs");
  const status = document.getElementById("wb-status");
  let lastForm = null;

  function url(path) {
    return path + "?token=" + encodeURIComponent(token) + "&sheet=" + encodeURIComponent(sheet);
  }

  function show(state) {
    if (state.html !== null) {
      report.innerHTML = state.html;
    }
    report.querySelectorAll(".wb-stopped").forEach(function (e) {
      e.classList.remove("wb-stopped");
    });
    (state.stopped || []).forEach(function (name) {
      const e = document.getElementById("def-" + name);
      if (e) {
        e.classList.add("wb-stopped");
      }
    });
    if (state.error) {
      banner.textContent = state.error;
      banner.hidden = false;
      body.classList.add("wb-failed");
    } else {
      banner.textContent = "";
      banner.hidden = true;
      body.classList.remove("wb-failed");
    }
    if (state.form !== null && state.form !== lastForm && !form.contains(document.activeElement)) {
      form.innerHTML = state.form;
      lastForm = state.form;
    }
    body.dataset.version = String(state.version);
  }

  function post(path, data) {
    return fetch(url(path), {
      method: "POST",
      headers: { "Content-Type": "application/json" },
      body: JSON.stringify(data || {}),
    }).then(function (r) { return r.json(); });
  }

  function inputText(label) {
    const select = label.querySelector("select");
    if (select) {
      return select.value;
    }
    const value = label.querySelector("[data-field=value]").value.trim();
    const unit = label.querySelector("[data-field=unit]");
    return unit && unit.value.trim() ? value + " " + unit.value.trim() : value;
  }

  form.addEventListener("submit", function (e) { e.preventDefault(); });
  form.addEventListener("change", function (e) {
    const label = e.target.closest("[data-input]");
    if (!label) {
      return;
    }
    const text = inputText(label);
    if (!text || /^\s/.test(text)) {
      return; // a field being emptied: nothing to send yet
    }
    const change = {};
    change[label.dataset.input] = text;
    const note = label.querySelector(".wb-input-error");
    post("/input", change).then(function (res) {
      note.textContent = res.error || "";
      label.classList.toggle("wb-refused", Boolean(res.error));
    });
  });
  document.querySelectorAll("button[data-action]").forEach(function (button) {
    button.addEventListener("click", function () {
      status.textContent = "...";
      post("/" + button.dataset.action).then(function (res) {
        status.textContent = res.error || res.message || "";
      });
    });
  });

  const events = new EventSource(url("/events"));
  events.addEventListener("update", function (e) { show(JSON.parse(e.data)); });
  events.addEventListener("error", function () { status.textContent = "server stopped?"; });
})();
