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

  // Only the parts of the report that changed are replaced (a section, a definition, a
  // table, a chart): the browser lays out again what is new, not the whole page.
  function same(a, b) {
    return a.nodeType === b.nodeType && (a.nodeType === 1 ? a.outerHTML === b.outerHTML
      : a.textContent === b.textContent);
  }

  function shell(e) {
    return e.cloneNode(false).outerHTML;
  }

  function morph(old, fresh, depth) {
    const a = Array.from(old.childNodes);
    const b = Array.from(fresh.childNodes);
    if (a.length !== b.length) {
      old.replaceChildren.apply(old, b);
      return;
    }
    for (let i = 0; i < a.length; i += 1) {
      if (same(a[i], b[i])) {
        continue;
      }
      if (depth > 0 && a[i].nodeType === 1 && b[i].nodeType === 1 && shell(a[i]) === shell(b[i])) {
        morph(a[i], b[i], depth - 1);
      } else {
        old.replaceChild(b[i], a[i]);
      }
    }
  }

  function show(state) {
    if (state.html !== null) {
      const fresh = document.createElement("template");
      fresh.innerHTML = state.html;
      morph(report, fresh.content, 2);
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
