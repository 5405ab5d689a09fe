// The site read from disk (file://, as /usr/share/doc/l6470emu/html is): the browser refuses the
// search page's fetch of each result's page for its summary, so the results come without one.
if (window.location.protocol === "file:" && typeof DOCUMENTATION_OPTIONS !== "undefined") {
  DOCUMENTATION_OPTIONS.SHOW_SEARCH_SUMMARY = false;
}
