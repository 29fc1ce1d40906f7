# asset_gallery --contact-sheet: runs the program into WORK_DIR and checks that the PNG exists
# with the expected size and that the legend has one row per asset (299 + a header row).
# Run: cmake -DPROGRAM=<asset_gallery> -DWORK_DIR=<dir> -P contact_sheet.cmake
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
execute_process(COMMAND "${PROGRAM}" --contact-sheet "${WORK_DIR}/sheet.png" --tile 32 --msaa 0 --columns 20
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "asset_gallery --contact-sheet failed (${rc}):\n${out}\n${err}")
endif()
if(NOT EXISTS "${WORK_DIR}/sheet.png" OR NOT EXISTS "${WORK_DIR}/sheet.csv")
  message(FATAL_ERROR "asset_gallery --contact-sheet wrote no sheet.png / sheet.csv")
endif()
file(STRINGS "${WORK_DIR}/sheet.csv" rows)
list(LENGTH rows n)
if(NOT n EQUAL 300)
  message(FATAL_ERROR "legend has ${n} lines, expected 300 (a header and 299 assets)")
endif()
list(GET rows 0 header)
if(NOT header STREQUAL "tile,row,column,id,kind,category,color,r,g,b,material,size,mass_kg")
  message(FATAL_ERROR "unexpected legend header: ${header}")
endif()
# PNG width and height (IHDR, bytes 16..23, big-endian): 20 columns x 15 rows of 32 px.
file(READ "${WORK_DIR}/sheet.png" ihdr OFFSET 16 LIMIT 8 HEX)
if(NOT ihdr STREQUAL "00000280000001e0")
  message(FATAL_ERROR "sheet.png size (IHDR ${ihdr}) is not 640 x 480")
endif()
