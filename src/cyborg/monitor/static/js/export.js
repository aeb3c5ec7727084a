// Save as DOT, SVG or PNG: what is shown (folded nodes stay folded) goes to the server, which
// draws it with Graphviz (POST /api/export); the answer is downloaded under the name the server
// gives. Returns {ok, message} for the page's message line.

export async function saveView({ ns, format, collapsed }) {
  const response = await fetch("/api/export", {
    method: "POST",
    headers: { "Content-Type": "application/json" },
    body: JSON.stringify({ ns, format, collapsed }),
  });
  if (!response.ok) return { ok: false, message: (await response.json()).error };
  const name = /filename="([^"]+)"/.exec(response.headers.get("Content-Disposition") || "")?.[1] || `tree.${format}`;
  const link = document.createElement("a");
  link.href = URL.createObjectURL(await response.blob());
  link.download = name;
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(link.href), 10000);
  return { ok: true, message: `saved ${name}` };
}
