# The characters of the program's UTF-8 help as groff names them (included by manpage.cmake and
# manpage_sub.cmake): man shows them in a UTF-8 locale and ASCII stand-ins (us, ^2, ->, x) under
# LC_ALL=C. groff has no ASCII stand-in for the micro sign (it prints "<micro>"): the page
# defines \*(Mc as "u" on the ascii device. groff_characters(VAR) rewrites the page in VAR.
function(groff_characters var)
  set(page "${${var}}")
  string(REPLACE "µ" "\\*(Mc" page "${page}")
  string(REPLACE "²" "\\(S2" page "${page}")
  string(REPLACE "→" "\\(->" page "${page}")
  string(REPLACE "×" "\\(mu" page "${page}")
  string(REPLACE "·" "\\(md" page "${page}")
  string(REPLACE "…" "..." page "${page}")
  string(REPLACE "–" "\\(en" page "${page}")
  string(REPLACE "—" "\\(em" page "${page}")
  string(REPLACE "\n.SH NAME" "\n.ie '\\*(.T'ascii' .ds Mc u\n.el .ds Mc \\(mc\n.SH NAME" page "${page}")
  set(${var} "${page}" PARENT_SCOPE)
endfunction()
