"""The bundled case files: installed as the package data ``semianalytic.cases`` (setup.py maps that
package onto this folder; :mod:`semianalytic.bundled` reads it).  No code lives here."""
