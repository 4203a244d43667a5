# Embeds the physical tables of data/ into the binaries, so that a program runs
# from any directory.  Each file becomes a byte array; embedded_file("name.csv")
# (common/data/embedded_files.h) returns its text.
set(SKYFARM_DATA_FILES
  cie1931_2deg_xyz.csv
  cie_d65.csv
  solar_am0.csv
  ozone_cross_section.csv
  ozone_profile.csv
  us_standard_atmosphere_1976.csv
  us_std_atm_1976_layers.csv
  elterman_1968_aerosol.csv
  rayleigh_bucholtz1995.csv
  cloud_mie_phase_water_reff10um.csv cloud_mie_water_summary.csv
  spa_periodic_terms.csv spa_nutation_terms.csv
  # Surfaces: optical constants and ground albedos (common/material/material_library.cpp).
  metal_nk_au_johnson_christy1972.csv metal_nk_ag_johnson_christy1972.csv
  metal_nk_cu_johnson_christy1972.csv metal_nk_al_rakic1995.csv metal_nk_cr_johnson_christy1974.csv
  water_nk_hale_querry1973.csv water_sellmeier_daimon_masumura2007_20C.csv
  ice_nk_warren_brandt2008.csv
  glass_n_bk7_sellmeier_schott.csv glass_n_bk7_k_schott.csv
  fused_silica_sellmeier_malitson1965.csv
  ground_albedo_feister_grewe1995.csv snow_albedo_bowker1985.csv
)

function(skyfarm_embed_data OUT_VAR)
  skyfarm_embed_files(out embedded_data skyfarm::embedded ${PROJECT_SOURCE_DIR}/data ${SKYFARM_DATA_FILES})
  set(${OUT_VAR} "${out}" PARENT_SCOPE)
endfunction()

function(skyfarm_embed_files OUT_VAR NAME NAMESPACE DIR)
  set(files ${ARGN})
  set(inputs "")
  foreach(f IN LISTS files)
    list(APPEND inputs "${DIR}/${f}")
  endforeach()
  file(RELATIVE_PATH label "${PROJECT_SOURCE_DIR}" "${DIR}")
  set(out "${PROJECT_BINARY_DIR}/generated/${NAME}.cpp")
  string(REPLACE ";" "|" files_arg "${files}")
  add_custom_command(
    OUTPUT "${out}"
    COMMAND ${CMAKE_COMMAND} -DDATA_DIR=${DIR} "-DFILES=${files_arg}" -DOUT=${out}
            -DNAMESPACE=${NAMESPACE} -DSOURCE_LABEL=${label}/
            -P ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    DEPENDS ${inputs} ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    COMMENT "Embedding ${NAME}"
    VERBATIM)
  set(${OUT_VAR} "${out}" PARENT_SCOPE)
endfunction()
