// ncplan serve: pan and zoom of the toolpath pictures, scroll sync of the two sources, and
// the review buttons' round trip. Everything else works without it.
(function () {
  "use strict";
  // Pan and zoom: the wheel zooms about the pointer, a drag pans; double-click resets.
  document.querySelectorAll("svg.toolpath").forEach(function (svg) {
    var vb0 = svg.getAttribute("viewBox").split(" ").map(Number);
    var vb = vb0.slice();
    var set = function () { svg.setAttribute("viewBox", vb.join(" ")); };
    var at = function (e) {
      var r = svg.getBoundingClientRect();
      return [vb[0] + (e.clientX - r.left) / r.width * vb[2], vb[1] + (e.clientY - r.top) / r.height * vb[3]];
    };
    svg.addEventListener("wheel", function (e) {
      e.preventDefault();
      var p = at(e), k = e.deltaY < 0 ? 0.8 : 1.25;
      vb = [p[0] - (p[0] - vb[0]) * k, p[1] - (p[1] - vb[1]) * k, vb[2] * k, vb[3] * k];
      set();
    }, { passive: false });
    var drag = null;
    svg.addEventListener("pointerdown", function (e) { drag = [e.clientX, e.clientY, vb[0], vb[1]]; svg.setPointerCapture(e.pointerId); });
    svg.addEventListener("pointermove", function (e) {
      if (!drag) return;
      var r = svg.getBoundingClientRect();
      vb[0] = drag[2] - (e.clientX - drag[0]) / r.width * vb[2];
      vb[1] = drag[3] - (e.clientY - drag[1]) / r.height * vb[3];
      set();
    });
    svg.addEventListener("pointerup", function () { drag = null; });
    svg.addEventListener("dblclick", function () { vb = vb0.slice(); set(); });
  });
  // Layers per workingstep.
  document.querySelectorAll("input[data-layer]").forEach(function (box) {
    box.addEventListener("change", function () {
      document.querySelectorAll('g.layer[data-layer="' + box.dataset.layer + '"]').forEach(function (g) {
        g.style.display = box.checked ? "" : "none";
      });
    });
  });
  // Scroll a source pane so that a line is in view, and flash it.
  var show = function (id) {
    var el = document.getElementById(id);
    if (!el) return;
    var pane = el.closest(".src");
    pane.scrollTop = el.offsetTop - pane.offsetTop - pane.clientHeight / 3;
    el.classList.add("flash");
    setTimeout(function () { el.classList.remove("flash"); }, 1500);
  };
  // A change's sentence: both sources to its lines, its regions highlighted.
  document.querySelectorAll("a.change").forEach(function (a) {
    a.addEventListener("click", function () {
      if (a.dataset.oline) show("o-" + a.dataset.oline);
      if (a.dataset.line) show("e-" + a.dataset.line);
      document.querySelectorAll("ul.sentences li.active, rect.region.active").forEach(function (x) { x.classList.remove("active"); });
      a.closest("li").classList.add("active");
      document.querySelectorAll('rect.region[data-change="' + a.dataset.change + '"]').forEach(function (r) { r.classList.add("active"); });
    });
  });
  // A line of one source: the other to its counterpart.
  document.querySelectorAll(".src .ln[data-pair]").forEach(function (ln) {
    ln.addEventListener("click", function () { show(ln.dataset.pair); });
  });
})();
