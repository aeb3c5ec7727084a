// Save as DOT, SVG or PNG: what is shown (folded nodes stay folded), under a name made of the
// tree's title. Returns {ok, message} for the page's message line.
//
// - DOT comes from the server (POST /api/export with the folded nodes): its text, for Graphviz.
// - SVG and PNG are drawn here from the page's own drawing of the tree, so saving needs no
//   Graphviz: the drawn nodes and edges, at the readable scale whatever the zoom, each with the
//   style it is shown with written on it (the file stands alone, without monitor.css), on
//   white. The PNG is that SVG painted on a canvas at twice its size (less for trees too large
//   for a canvas: MAX_PNG_SIDE, MAX_PNG_PIXELS).

const SVG_NS = "http://www.w3.org/2000/svg";
const STYLED = ["fill", "stroke", "stroke-width", "stroke-dasharray", "opacity", "font-size",
  "font-family", "font-weight", "text-anchor", "dominant-baseline"];
const PNG_SCALE = 2;
const MAX_PNG_SIDE = 16000;
const MAX_PNG_PIXELS = 120e6;

export async function saveView({ ns, format, collapsed, svg, bounds, title }) {
  if (format === "svg" || format === "png") {
    const text = standaloneSvg(svg, bounds);
    const blob = format === "svg" ? new Blob([text], { type: "image/svg+xml" }) : await pngOf(text, bounds);
    return download(blob, `${fileStem(title)}.${format}`);
  }
  const response = await fetch("/api/export", {
    method: "POST",
    headers: { "Content-Type": "application/json" },
    body: JSON.stringify({ ns, format, collapsed }),
  });
  if (!response.ok) return { ok: false, message: (await response.json()).error };
  const name = /filename="([^"]+)"/.exec(response.headers.get("Content-Disposition") || "")?.[1] || `tree.${format}`;
  return download(await response.blob(), name);
}

// The file name the server gives the same tree (monitor/export.py's render).
function fileStem(title) {
  return (title || "").replace(/[^A-Za-z0-9_.-]+/g, "_").replace(/^_+|_+$/g, "") || "behaviour_tree";
}

function download(blob, name) {
  const link = document.createElement("a");
  link.href = URL.createObjectURL(blob);
  link.download = name;
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(link.href), 10000);
  return { ok: true, message: `saved ${name}` };
}

// The tree drawn in `svg` (its #viewport) as an SVG document of its own, `bounds` (the drawing's
// {x0, y0, x1, y1}) at scale 1.
export function standaloneSvg(svg, bounds) {
  const viewport = svg.querySelector("#viewport");
  // labels are left out of a view zoomed far out (svg.far): style them as they are when shown
  const far = svg.classList.contains("far");
  svg.classList.remove("far");
  const copy = viewport.cloneNode(true);
  copy.removeAttribute("transform");
  copy.removeAttribute("id");
  const shown = viewport.querySelectorAll("*"), copied = copy.querySelectorAll("*");
  for (let i = 0; i < shown.length; i++) {
    const computed = getComputedStyle(shown[i]);
    const style = STYLED.map((name) => `${name}:${computed.getPropertyValue(name)}`);
    if (shown[i].tagName === "rect") {
      copied[i].setAttribute("rx", computed.getPropertyValue("rx").replace("px", "") || "0");
    }
    copied[i].setAttribute("style", style.join(";"));
    copied[i].removeAttribute("class");
  }
  svg.classList.toggle("far", far);
  const width = Math.ceil(bounds.x1 - bounds.x0), height = Math.ceil(bounds.y1 - bounds.y0);
  const root = document.createElementNS(SVG_NS, "svg");
  root.setAttribute("xmlns", SVG_NS);
  root.setAttribute("width", String(width));
  root.setAttribute("height", String(height));
  root.setAttribute("viewBox", `${bounds.x0} ${bounds.y0} ${width} ${height}`);
  const background = document.createElementNS(SVG_NS, "rect");
  for (const [name, value] of [["x", bounds.x0], ["y", bounds.y0], ["width", width], ["height", height], ["fill", "#fff"]]) {
    background.setAttribute(name, String(value));
  }
  root.append(background, copy);
  return `<?xml version="1.0" encoding="UTF-8"?>\n${new XMLSerializer().serializeToString(root)}\n`;
}

// The SVG `text` painted into a PNG blob.
async function pngOf(text, bounds) {
  const width = bounds.x1 - bounds.x0, height = bounds.y1 - bounds.y0;
  const scale = Math.min(PNG_SCALE, MAX_PNG_SIDE / width, MAX_PNG_SIDE / height, Math.sqrt(MAX_PNG_PIXELS / (width * height)));
  const url = URL.createObjectURL(new Blob([text], { type: "image/svg+xml" }));
  try {
    const image = new Image();
    image.src = url;
    await image.decode();
    const canvas = document.createElement("canvas");
    canvas.width = Math.max(1, Math.round(width * scale));
    canvas.height = Math.max(1, Math.round(height * scale));
    canvas.getContext("2d").drawImage(image, 0, 0, canvas.width, canvas.height);
    return await new Promise((resolve, reject) => {
      canvas.toBlob((blob) => (blob ? resolve(blob) : reject(new Error("the PNG could not be made"))), "image/png");
    });
  } finally {
    URL.revokeObjectURL(url);
  }
}
