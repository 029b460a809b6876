// radar gallery: the overview (search, status filter, sort by status, id, title, the scores in DATA.scores or the
// material, pages of thumbnails) and one object's detail view (3D mesh in <model-viewer>, relit under its own
// recovered lighting or a built-in environment).
// Data comes from data.js (window.RADAR_GALLERY, written by radar_cli/derender/present/gallery.py). Text from the
// results is only ever set as textContent, never parsed as HTML.
"use strict";
(function () {
  const DATA = window.RADAR_GALLERY || { objects: [], builtin_envs: [], failed: 0, scores: [] };
  for (const o of DATA.objects) o.views = o.views || []; // data.js written before objects had several views
  const PAGE_SIZE = 120;
  // objects of known size (meshes in metres) are all seen from this far, so their sizes compare on screen
  const REAL_SIZE_DISTANCE = "2m";
  const REAL_SIZE_FOV = "30deg";
  const STATUS_ORDER = { failed: 0, review: 1, unknown: 2, ok: 3 };
  const FROM_DISK = location.protocol === "file:";
  const byId = new Map(DATA.objects.map((o) => [o.id, o]));
  const state = { query: "", status: "all", sort: "status", page: 0 };

  function el(tag, attrs, ...children) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (v === null || v === undefined || v === false) continue;
      if (k === "text") node.textContent = v;
      else if (k === "onclick") node.addEventListener("click", v);
      else node.setAttribute(k, v === true ? "" : v);
    }
    for (const c of children) if (c) node.append(c);
    return node;
  }
  const path = (id, file) => encodeURIComponent(id) + "/" + file;
  const objectHash = (id) => "#obj=" + encodeURIComponent(id);
  const fmt = (v, digits) => (v === null || v === undefined ? "–" : Number(v).toFixed(digits));
  const badge = (status) => el("span", { class: "badge " + status, text: status });

  function sortKeys() {
    const keys = [
      ["status", "status (failed, review first)"],
      ["id", "id"],
      ["title", "title"],
    ];
    for (const s of DATA.scores)
      keys.push(["score:" + s + ":asc", s + " ascending"], ["score:" + s + ":desc", s + " descending"]);
    for (const m of ["pitch", "alpha", "rho"])
      keys.push(["material:" + m + ":asc", m + " ascending"], ["material:" + m + ":desc", m + " descending"]);
    return keys;
  }

  function compare(a, b) {
    const key = state.sort;
    if (key === "status")
      return (STATUS_ORDER[a.status] ?? 2) - (STATUS_ORDER[b.status] ?? 2) || a.id.localeCompare(b.id);
    if (key === "id") return a.id.localeCompare(b.id);
    if (key === "title") return title(a).localeCompare(title(b)) || a.id.localeCompare(b.id);
    const [group, name, dir] = key.split(":");
    const va = (group === "score" ? a.scores : a.material)[name],
      vb = (group === "score" ? b.scores : b.material)[name];
    if (va === null || va === undefined) return vb === null || vb === undefined ? a.id.localeCompare(b.id) : 1;
    if (vb === null || vb === undefined) return -1; // objects without the score go last either way
    return (dir === "asc" ? va - vb : vb - va) || a.id.localeCompare(b.id);
  }

  const title = (o) => (o.attribution && o.attribution.title) || "";

  function visible() {
    const q = state.query.trim().toLowerCase();
    return DATA.objects
      .filter(
        (o) =>
          (state.status === "all" || o.status === state.status) &&
          (!q || o.id.toLowerCase().includes(q) || title(o).toLowerCase().includes(q) || o.status.includes(q)),
      )
      .sort(compare);
  }

  function card(o) {
    const open = () => {
      location.hash = objectHash(o.id);
    };
    const img = o.thumbnail
      ? el("img", { src: path(o.id, "thumbnail.png"), loading: "lazy", width: 256, height: 128, alt: o.id })
      : null;
    const node = el(
      "div",
      { class: "card", tabindex: 0, role: "link", "data-id": o.id, onclick: open },
      img,
      el("div", { class: "id", text: o.id + " " }, badge(o.status)),
      title(o) ? el("div", { class: "title", text: title(o), title: title(o) }) : null,
      o.views.length ? viewStrip(o, "mini") : null,
    );
    node.addEventListener("keydown", (e) => {
      if (e.key === "Enter") open();
    });
    return node;
  }

  // one photograph of an object seen from several sides: "front, 0°" or "top, left out: <why>"
  const viewTurn = (v) => (v.used ? fmt(v.turn_deg, 0) + "°" : "left out");
  const viewLabel = (v) => v.name + ", " + (v.used ? viewTurn(v) + ", used" : "left out" + (v.reason ? ": " + v.reason : ""));

  function viewStrip(o, kind) {
    // the card's strip shows each view's photograph (the left half of its picture); the detail view the whole
    // picture (photograph | the object drawn as that view sees it) and why a view was left out
    const strip = el("div", { class: "views " + kind, "aria-label": o.views.length + " views" });
    for (const v of o.views) {
      const img = v.picture
        ? el("img", {
            src: path(o.id, v.picture),
            loading: "lazy",
            alt: v.name,
            width: kind === "mini" ? 44 : null,
            height: kind === "mini" ? 44 : 128,
          })
        : el("div", { class: "missing", text: "unreadable" });
      const caption =
        kind === "mini"
          ? el("figcaption", {}, el("div", { text: v.name }), el("div", { text: viewTurn(v) }))
          : el("figcaption", {}, el("b", { text: v.name }), el("br"), v.used ? viewTurn(v) + " · used" : "left out",
              v.used || !v.reason ? null : el("span", { class: "reason", text: ": " + v.reason }));
      strip.append(el("figure", { class: v.used ? "used" : "left-out", title: viewLabel(v) }, img, caption));
    }
    return strip;
  }

  function renderOverview() {
    const list = visible();
    const pages = Math.max(1, Math.ceil(list.length / PAGE_SIZE));
    state.page = Math.min(state.page, pages - 1);
    const grid = document.getElementById("grid");
    grid.replaceChildren(...list.slice(state.page * PAGE_SIZE, (state.page + 1) * PAGE_SIZE).map(card));
    const pager = document.getElementById("pager");
    const go = (p) => () => {
      state.page = p;
      renderOverview();
      window.scrollTo(0, 0);
    };
    pager.replaceChildren(
      el("span", { text: `${list.length} shown, page ${state.page + 1}/${pages} ` }),
      el("button", { text: "‹ prev", disabled: state.page === 0, onclick: go(state.page - 1) }),
      el("button", { text: "next ›", disabled: state.page >= pages - 1, onclick: go(state.page + 1) }),
    );
  }

  function setupToolbar() {
    const counts = {};
    for (const o of DATA.objects) counts[o.status] = (counts[o.status] || 0) + 1;
    const status = document.getElementById("status");
    status.append(el("option", { value: "all", text: `all statuses (${DATA.objects.length})` }));
    for (const s of Object.keys(STATUS_ORDER))
      if (counts[s]) status.append(el("option", { value: s, text: `${s} (${counts[s]})` }));
    const sort = document.getElementById("sort");
    for (const [value, label] of sortKeys()) sort.append(el("option", { value, text: "sort: " + label }));
    const search = document.getElementById("search");
    search.addEventListener("input", () => {
      state.query = search.value;
      state.page = 0;
      renderOverview();
    });
    status.addEventListener("change", () => {
      state.status = status.value;
      state.page = 0;
      renderOverview();
    });
    sort.addEventListener("change", () => {
      state.sort = sort.value;
      state.page = 0;
      renderOverview();
    });
    if (DATA.failed) {
      const failed = document.getElementById("failed");
      failed.append(
        `${DATA.failed} input(s) could not be de-rendered: see `,
        el("a", { href: "failures.csv", text: "failures.csv" }),
        ".",
      );
    }
  }

  const scripts = new Map();
  function loadScript(src) {
    // the 1 MB viewer (and from disk the built-in lighting) is read only when needed
    if (!scripts.has(src)) {
      scripts.set(
        src,
        new Promise((resolve, reject) => {
          const s = el("script", { src });
          s.onload = resolve;
          s.onerror = () => reject(new Error("could not load " + src));
          document.head.append(s);
        }),
      );
    }
    return scripts.get(src);
  }

  // model-viewer reads a lighting file as HDR only when its address ends in .hdr: blob addresses get a fragment
  const hdrBlob = (blob, name) => URL.createObjectURL(blob) + "#" + name + ".hdr";

  async function diskEnvironments() {
    // from disk the built-in .hdr files cannot be fetched: env.js holds them
    await loadScript(".gallery/env.js");
    return Object.entries(window.RADAR_ENVS || {}).map(([name, b64]) => {
      const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
      return [name, hdrBlob(new Blob([bytes]), name)];
    });
  }

  function viewer(o) {
    const box = el("div", { class: "viewer" });
    if (!FROM_DISK) {
      const envs = o.viewer_env ? [["recovered", path(o.id, "env_viewer.hdr")]] : [];
      for (const e of DATA.builtin_envs) envs.push([e, ".gallery/env/" + e + ".hdr"]);
      showModel(box, o, path(o.id, "mesh.glb"), envs);
      return box;
    }
    const picker = el("input", { type: "file", accept: ".glb,.hdr", multiple: true, "aria-label": "choose mesh.glb" });
    box.append(
      el("p", {
        class: "note",
        text:
          "Opened from disk, the browser lets this page read only the files you " +
          "choose: pick mesh.glb (and env_viewer.hdr, its recovered lighting) in the folder " +
          o.id +
          "/ for the 3D " +
          "view, or run `radar serve RESULTS` and open the address it prints.",
      }),
      picker,
    );
    picker.addEventListener("change", async () => {
      const files = [...picker.files];
      const glb = files.find((f) => f.name.toLowerCase().endsWith(".glb"));
      const hdr = files.find((f) => f.name.toLowerCase().endsWith(".hdr"));
      if (!glb) {
        box.append(el("p", { class: "note", text: "No .glb file among those chosen." }));
        return;
      }
      let envs = hdr ? [["recovered", hdrBlob(hdr, "recovered")]] : [];
      try {
        envs = envs.concat(await diskEnvironments());
      } catch (e) {
        box.append(el("p", { class: "note", text: e.message }));
      }
      box.replaceChildren();
      showModel(box, o, URL.createObjectURL(glb), envs);
    });
    return box;
  }

  function showModel(box, o, src, envs) {
    const mv = el("model-viewer", {
      src,
      alt: "3D mesh of " + o.id,
      "camera-controls": true,
      "interaction-prompt": "none",
      "shadow-intensity": "0",
      exposure: "1",
      "environment-image": envs.length ? envs[0][1] : null,
      "camera-orbit": "0deg 80deg " + (o.size ? REAL_SIZE_DISTANCE : "auto"),
      "field-of-view": o.size ? REAL_SIZE_FOV : null,
    });
    const buttons = el("div", { class: "envs" }, el("span", { text: "Lighting: " }));
    const skybox = el("input", { type: "checkbox" });
    const apply = (url) => {
      mv.setAttribute("environment-image", url);
      if (skybox.checked) mv.setAttribute("skybox-image", url);
      else mv.removeAttribute("skybox-image");
      for (const b of buttons.querySelectorAll("button")) b.setAttribute("aria-pressed", String(b.dataset.url === url));
    };
    for (const [name, url] of envs) {
      buttons.append(
        el("button", {
          "data-url": url,
          "aria-pressed": String(url === envs[0][1]),
          text: name,
          onclick: () => apply(url),
        }),
      );
    }
    skybox.addEventListener("change", () => apply(mv.getAttribute("environment-image")));
    const exposure = el("input", {
      type: "range",
      min: "0.1",
      max: "4",
      step: "0.1",
      value: "1",
      "aria-label": "exposure",
    });
    exposure.addEventListener("input", () => mv.setAttribute("exposure", exposure.value));
    mv.addEventListener("error", () =>
      box.append(el("p", { class: "note", text: "The viewer could not load the mesh of " + o.id + "." })),
    );
    box.append(mv, buttons, el("label", {}, skybox, " show the environment "), el("label", {}, " exposure ", exposure));
    box.append(
      el("p", {
        class: "note",
        text: o.size
          ? `Real size: ${fmt(o.size.mesh_cm.height, 1)} cm high, seen from ${REAL_SIZE_DISTANCE} ` +
            "(as every object of known size); drag to turn, scroll to come closer."
          : "Size unknown: the mesh is unitless and framed to fit.",
      }),
    );
    loadScript(".gallery/model-viewer-umd.min.js").catch((e) =>
      box.append(el("p", { class: "note", text: e.message })),
    );
  }

  function info(o) {
    const rows = [
      ["status", o.status],
      ["reasons", o.reasons.join("; ") || "–"],
    ];
    if (o.cut_edges.length) rows.push(["cut edges", o.cut_edges.join(", ")]);
    for (const [k, v] of Object.entries(o.scores)) rows.push([k, fmt(v, 3)]);
    const m = o.material;
    rows.push(
      ["pitch", fmt(m.pitch, 1) + "°"],
      ["roll", fmt(m.roll, 1) + "°"],
      ["shininess", fmt(m.alpha, 0)],
      ["specular albedo", fmt(m.rho, 2)],
      ["roughness (glTF)", fmt(m.roughness, 2)],
    );
    if (o.size) {
      const plain = ["height", "width", "diameter"];
      for (const [k, v] of Object.entries(o.size.cm))
        rows.push([plain.includes(k) ? k : k + " diameter", fmt(v, 1) + " cm"]);
      rows.push(["size from", o.size.source], ["mesh widest", fmt(o.size.mesh_cm.max_diameter, 1) + " cm"]);
    }
    const table = el(
      "table",
      { class: "values" },
      ...rows.map(([k, v]) => el("tr", {}, el("td", { text: k }), el("td", { text: v }))),
    );
    const box = el("div", { class: "info" }, table);
    const a = o.attribution;
    if (a) {
      const credit = el(
        "p",
        { class: "attribution" },
        el("b", { text: a.title || "untitled" }),
        el("br"),
        [a.credit, a.licence].filter(Boolean).join(" · "),
      );
      if (a.url)
        credit.append(el("br"), el("a", { href: a.url, rel: "noopener", target: "_blank", text: "catalogue record" }));
      box.append(credit);
    }
    const links = el("p", {});
    for (const [label, file] of [
      ["GLB", "mesh.glb"],
      ["OBJ", "mesh.obj"],
      ["material.json", "material.json"],
      ["albedo", "albedo.png"],
      ["lighting (HDR)", "env_map.hdr"],
    ])
      links.append(el("a", { href: path(o.id, file), text: label }), " ");
    box.append(links);
    return box;
  }

  function pictures(o) {
    const figs = [
      ["input.png", "input"],
      ["recon.png", "reconstruction"],
      ["albedo_rendered.png", "albedo"],
      ["normal_rendered.png", "normals"],
      ["material_sphere.png", "material"],
      ["env_map.png", "recovered lighting"],
      ["turntable.gif", "turntable"],
    ];
    if (o.appendages) figs.push(["appendages.png", "appendages"]);
    for (const e of o.relit) figs.push(["relit_" + e + ".png", "relit: " + e]);
    const box = el("div", { class: "pictures" });
    for (const [file, label] of figs) {
      const img = el("img", { src: path(o.id, file), loading: "lazy", alt: label });
      img.addEventListener("error", () => img.parentElement && img.parentElement.remove());
      box.append(el("figure", {}, img, el("figcaption", { text: label })));
    }
    const fused = o.views.some((v) => v.used);
    box.append(
      el(
        "figure",
        {},
        el("img", { src: path(o.id, "albedo.png"), class: "wide", loading: "lazy", alt: "albedo 360" }),
        el("figcaption", {
          text: fused
            ? "albedo, unwrapped 360°, fused from the used views (the 3D view and the turntable carry it)"
            : "albedo, unwrapped 360° (the back mirrored from the front)",
        }),
      ),
    );
    if (o.coverage)
      box.append(
        el(
          "figure",
          {},
          el("img", { src: path(o.id, "coverage.png"), class: "wide", loading: "lazy", alt: "coverage" }),
          el("figcaption", { text: "which view gave each texel (in the views' order: red, green, blue, yellow; black: none)" }),
        ),
      );
    return box;
  }

  function renderDetail(id) {
    const o = byId.get(id);
    const detail = document.getElementById("detail");
    if (!o) {
      detail.replaceChildren(el("p", { class: "note", text: "No object " + id + " in this gallery." }));
      return;
    }
    const list = visible(),
      at = list.findIndex((x) => x.id === id);
    const nav = el("p", {}, el("a", { href: "#", text: "← all objects" }));
    if (at > 0)
      nav.append(" · ", el("a", { href: objectHash(list[at - 1].id), text: "‹ " + list[at - 1].id }));
    if (at >= 0 && at < list.length - 1)
      nav.append(" · ", el("a", { href: objectHash(list[at + 1].id), text: list[at + 1].id + " ›" }));
    detail.replaceChildren(
      nav,
      el("h2", { text: o.id + " " }, badge(o.status)),
      el("div", { class: "cols" }, viewer(o), info(o)),
      o.views.length ? el("h3", { text: `${o.views.length} photographs, ${o.views.filter((v) => v.used).length} used` }) : null,
      o.views.length ? viewStrip(o, "full") : null,
      pictures(o),
    );
    document.title = "radar: " + o.id;
  }

  function route() {
    const match = location.hash.match(/^#obj=(.+)$/);
    const overview = document.getElementById("overview"),
      detail = document.getElementById("detail");
    overview.hidden = Boolean(match);
    detail.hidden = !match;
    document.getElementById("toolbar").hidden = Boolean(match);
    if (match) {
      renderDetail(decodeURIComponent(match[1]));
      window.scrollTo(0, 0);
    } else {
      detail.replaceChildren();
      document.title = "radar: " + DATA.objects.length + " de-rendered objects";
    }
  }

  setupToolbar();
  renderOverview();
  window.addEventListener("hashchange", route);
  route();
})();
