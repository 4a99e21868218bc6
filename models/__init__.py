"""The bundled example models. The build ships this folder inside the package as `mbplanar.examples`
(setup.py); `mbplanar.formats.list_examples` lists them and ``mbplanar examples`` copies them out."""
