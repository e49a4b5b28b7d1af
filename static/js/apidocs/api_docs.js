// /api/docs: Swagger UI (vendored, window.SwaggerUIBundle) renders the app's own description.
const root = document.getElementById("swagger-ui");

window.SwaggerUIBundle({
  url: root.dataset.specUrl,
  domNode: root,
  validatorUrl: null, // never send the document to validator.swagger.io: the robot may be offline
  deepLinking: true,
  tryItOutEnabled: false, // calls that move the robot should be deliberate, not one click away
  docExpansion: "none", // 26 sections, 127 operations: each opens on a click (all at once did not render)
  // Swagger UI's server list has a visible "Servers" title but no label a screen reader links to it.
  onComplete: () => {
    const servers = document.getElementById("servers");
    if (servers && !servers.hasAttribute("aria-label")) servers.setAttribute("aria-label", "Servers");
  },
});
